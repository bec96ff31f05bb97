# cltess tessellate --pixels --camera-path (24 frames to PLY), this tree against a baseline tree,
# alternating; wall seconds of the whole command (Python start, imports, the scene, every frame
# written).  bash campath_ab.sh THIS_TREE BASELINE_TREE SCENE PIXELS ROUNDS
this=$1; base=$2; scene=$3; px=$4; rounds=${5:-4}
for r in $(seq 1 $rounds); do
  for t in $this $base; do
    rm -rf /tmp/campath/out; mkdir -p /tmp/campath/out
    s=$(date +%s.%N)
    PYTHONPATH=$t python -m cltess tessellate $scene --pixels $px --camera-path /tmp/campath/orbit.json \
      -o /tmp/campath/out/f_{frame:03d}.ply -q $EXTRA || exit 1
    e=$(date +%s.%N)
    echo "$(basename $t) $(echo "$e - $s" | bc)"
  done
done
