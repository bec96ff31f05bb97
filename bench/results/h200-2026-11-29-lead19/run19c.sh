# Session 19, H200, call 3: staged_rows (a line's work-item walks; the normal in the write-out) against
# prepared_rows; chunk sizes and register caps. Carry [".whl", "probe/gpu19"].
. bench/gpu_setup.sh >/dev/null || exit 1
R=$OUT/call3; mkdir -p $R
CLTESS_DEVICE=nvidia timeout 120 python3 -m pytest -o addopts="" -q -p no:cacheprovider -x tests/test_staged_probe.py > $R/tests.txt 2>&1
tail -2 $R/tests.txt
python3 bench/gpu_stage45.py --device nvidia --repeat 10 --json $R/rows2.json \
  --variant rows rows-prep . - \
  --variant staged4 staged-prep . - \
  --variant staged2 staged-prep . opt:-DSTAGED_CHUNK=2 \
  --variant staged8 staged-prep . opt:-DSTAGED_CHUNK=8 \
  --variant staged16 staged-prep . opt:-DSTAGED_CHUNK=16 \
  --variant cap128 staged-prep . "opt:-DSTAGED_NO_REQD=1 -cl-nv-maxrregcount=128" \
  --variant cap96 staged-prep . "opt:-DSTAGED_NO_REQD=1 -cl-nv-maxrregcount=96" \
  --variant staged4/16 staged-prep/16 . - \
  --variant nofall staged-prep . opt:-DPROBE_NO_FALLBACK=1 \
  --variant rows-again rows-prep . - 2>&1 | grep -v "Warning\|lambda\|_build\|prg.build\|RepeatedKernel\|Kernel(prg" > $R/rows2.txt
grep "registers\|^|" $R/rows2.txt | tail -24
