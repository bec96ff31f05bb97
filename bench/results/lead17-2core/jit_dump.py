"""Session 17: where Intel's CPU runtime spends stage 4, instruction by instruction.  Its JIT code
has no symbols for perf, so this runs a script (bench/perf_stages.py) and, when it prints
"perf_stages: end", copies every executable mapping that is not a library into
/tmp/s17/jit/region-<address>.bin.  Used as:
    perf record -e cpu-clock -F 2000 -o st4.data -- python jit_dump.py bench/perf_stages.py --device intel --stage 4 --launches 12
    perf script -i st4.data -F ip > ips.txt; python jit_hist.py ips.txt 30; python jit_annotate.py LO HI
"""
import sys, runpy, builtins
def dump():
    out = []
    with open("/proc/self/maps") as maps:
        for line in maps:
            parts = line.split()
            if "x" not in parts[1]:
                continue
            path = parts[5] if len(parts) >= 6 else ""
            if path.endswith(".so") or ".so." in path or path.startswith("/usr") or path.startswith("/root/.pyenv") or path == "[vdso]" or path == "[vsyscall]":
                continue
            lo, hi = (int(x, 16) for x in parts[0].split("-"))
            try:
                with open("/proc/self/mem", "rb") as mem:
                    mem.seek(lo); data = mem.read(hi - lo)
            except OSError:
                continue
            name = f"/tmp/s17/jit/region-{lo:x}.bin"
            open(name, "wb").write(data); out.append((hex(lo), hex(hi), path))
    sys.stderr.write(f"JIT regions: {out}\n")
real_print = builtins.print
def print_and_dump(*args, **kwargs):
    real_print(*args, **kwargs)
    if any("perf_stages: end" in str(a) for a in args):
        dump()
builtins.print = print_and_dump
sys.argv = sys.argv[1:]
runpy.run_path(sys.argv[0], run_name="__main__")
