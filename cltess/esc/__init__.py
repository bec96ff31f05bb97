"""ESC (Hu et al., GRAPP 2014): distance-test adaptive tessellation of bicubic Bézier patches
with virtual vertices.  docs/esc.md.  The pattern is cltess/patterns/esc.py; here the evaluator
(evaluate.py), the distance test and levels (masks.py) and the host pipeline (tessellate.py)."""
