# Session 19, H200, call 8: the final tree's stage 4-5 tests (test_triangles_mirror now with an
# output that is not 8-byte aligned). Carry [".whl", "probe/gpu19"].
. bench/gpu_setup.sh >/dev/null || exit 1
R=$OUT/call8; mkdir -p $R
CLTESS_DEVICE=nvidia timeout 200 python3 -m pytest -o addopts="" -q -p no:cacheprovider -W error::pytest.PytestUnraisableExceptionWarning \
  tests/test_triangles_mirror.py tests/test_work_points.py tests/test_triangle_at.py tests/test_frame_capacity.py > $R/tests.txt 2>&1
tail -1 $R/tests.txt
