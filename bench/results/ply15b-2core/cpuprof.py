"""cProfile of one CLI command with a CPU-time clock (process CPU, all threads): where a child's
CPU seconds go on a loaded machine.  Usage, e.g. (warm scene cache, then look at the dump):

    CLTESS_SCENE_CACHE=/tmp/c python cpuprof.py warm.prof tessellate teapots30k.bpt --eps 0.0085 --no-weld -q -o out.ply
    python -c "import pstats; pstats.Stats('warm.prof').sort_stats('cumulative').print_stats(60)"
"""
import cProfile, sys, time
out = sys.argv[1]; sys.argv = ["cltess"] + sys.argv[2:]
prof = cProfile.Profile(time.process_time)
prof.enable()
import cltess.cli
try:
    cltess.cli.main(sys.argv[1:])
except SystemExit:
    pass
prof.disable()
prof.dump_stats(out)
