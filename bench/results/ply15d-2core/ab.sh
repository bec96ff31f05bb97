# ab.sh N "ENV1" "ENV2" ... : alternate cold timeline runs of this tree with each env setting; print key lines
. /work/main/.venv/bin/activate; cd /tmp/prof
n=$1; shift
for i in $(seq $n); do for envs in "$@"; do
  rm -rf /tmp/prof/c6
  tree=/work/wt/ply15d; [ "$envs" = base ] && tree=/tmp/ply15d-base
  e=$envs; [ "$envs" = base ] && e=A=0; out=$(env $e PYTHONPATH=$tree CLTESS_SCENE_CACHE=/tmp/prof/c6 /tmp/prof/others.sh python timeline.py tessellate /tmp/t30d/scene.bpt --eps 0.0085 --no-weld -q -o /tmp/t30d/out-ab.ply 2>&1)
  echo "$envs| $(echo "$out" | grep -E "^ *(_fast_bpt|edge_groups|orient_scene|prepare_scene|total|tessellate_to_file|plan) |process|others" | sed 's/  */ /g' | tr '\n' '|')"
done; done
