# session 17, the last call: cltess devices on the H200 (the sharing column), the sharing unit tests
. bench/gpu_setup.sh >/dev/null || exit 1
GPU_SETUP_POCL=1 . bench/gpu_setup.sh >/dev/null
python3 -m cltess devices 2>&1 | grep -v "Warn\|prg.build\|_create_built" | tee $OUT/devices.txt
CLTESS_DEVICE=nvidia timeout 200 python3 -m pytest -o addopts="" -q -p no:cacheprovider tests/test_share_cuda.py tests/test_cli.py -k "devices or apis or share or refuses" 2>&1 | tail -3 | tee $OUT/tests-devices.txt
