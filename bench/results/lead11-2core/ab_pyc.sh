#!/bin/bash
# alternate: source compile each start (as this shell) vs cached bytecode (a user's install)
PY=/work/main/.venv/bin/python
env -u PYTHONDONTWRITEBYTECODE PYTHONPYCACHEPREFIX=/tmp/pycache $PY -c "import cltess.cli, cltess.stream, cltess.orient, cltess.io, cltess.device, cltess.backends.opencl.tessellator, cltess.io.bpt, cltess.crack.adjacency" 
for i in $(seq 1 $1); do
  for v in src pyc; do
    C=$(mktemp -d)
    if [ $v = src ]; then E="env CLTESS_SCENE_CACHE=$C"; else E="env -u PYTHONDONTWRITEBYTECODE PYTHONPYCACHEPREFIX=/tmp/pycache CLTESS_SCENE_CACHE=$C"; fi
    /usr/bin/time -f "$v %e wall %U user %S sys" $E $PY -m cltess tessellate scene.bpt --orient --eps 0.0085 --no-weld -q -o out-$v.ply
    rm -rf $C
  done
done
