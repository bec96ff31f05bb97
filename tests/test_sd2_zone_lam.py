"""The tie zone's weights (w, lam) of kernels/patterns/sd2.h sd2_morph against the NumPy mirror
cltess/patterns/sd2.py sd2_morph, bitwise, on hinted records chosen to reach every branch of the
sharpening near odd whole factors (docs/sd2.md section 5, "Seventh pass"): plateaus at odd whole
numbers left by one or two corners (sigma_m = 0, kappa from sigma alone, down to 0 at a tie),
isolated triple ties just off odd numbers (kappa from sigma_m / rho), ties with c+1 and c+2
(lam exactly 1 and 0), and random zone records."""
import numpy as np
import pyopencl as cl

from cltess.backends.opencl.programs import correctly_rounded_division, kernel_dir
from cltess.patterns.fractional import FIXED_ONE
from cltess.patterns.sd2 import HINT_SHIFT, _sharpen, _switch_width, odd_distance, sd2_morph, sd2_shape

KERNEL = """
__kernel void morph(__global const int4 *records, int count, __global int *zone, __global float2 *weights)
{
    int id = get_global_id(0);
    if (id >= count) return;
    int4 f = records[id];
    int tip;
    float w = -1.0f, lam = -1.0f;
    zone[id] = sd2_shape(f, &tip) == SD2_FAN ? sd2_morph(f, tip, &w, &lam) : -1;
    weights[id] = (float2)(w, lam);
}
"""


def hinted(phi) -> list:
    phi = [int(x) for x in phi]
    m = int(np.argmin(phi))
    return [max(phi[e], phi[(e + 1) % 3]) for e in range(3)] + [(phi[m] << HINT_SHIFT) | m]


def records(rng, count=3000) -> np.ndarray:
    out = []
    for _ in range(count):
        kind = rng.integers(0, 4)
        n = int(2 * rng.integers(0, 8) + 1) * FIXED_ONE  # an odd whole number
        d = int(rng.integers(0, FIXED_ONE))
        if kind == 0:  # a plateau at n left by the tip, its c+1 or c+2 at a fraction of its rate
            phi = [n + d, n + int(rng.random() * d) * int(rng.integers(0, 2)), n + int(rng.random() * d)]
        elif kind == 1:  # near an isolated triple tie just off an odd number
            centre = n + int(rng.integers(-FIXED_ONE // 8, FIXED_ONE // 8))
            phi = [max(centre + int(rng.integers(-400, 400)), FIXED_ONE) for _ in range(3)]
        elif kind == 2:  # a tie of the tip with one base corner, the other below
            top = int(rng.integers(FIXED_ONE, 20 * FIXED_ONE))
            phi = [top, top, max(top - int(rng.integers(1, FIXED_ONE)), FIXED_ONE)]
        else:  # anywhere in (or near) the zone
            top = int(rng.integers(FIXED_ONE, 30 * FIXED_ONE))
            phi = [top] + [max(top - int(rng.integers(0, 2 * FIXED_ONE)), FIXED_ONE) for _ in range(2)]
        out.append(hinted([phi[k] for k in rng.permutation(3)]))
    return np.array(out, np.int32)


def test_zone_weights_equal_the_mirror_bitwise(tessellator, rng):
    recs = records(rng)
    ctx, queue = tessellator.context, tessellator.queue
    program = cl.Program(ctx, '#include "patterns/sd2.h"\n' + KERNEL).build(
        options=["-I", str(kernel_dir())] + correctly_rounded_division(ctx.devices[0]))
    mf = cl.mem_flags
    source = cl.Buffer(ctx, mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=recs)
    zone = np.zeros(len(recs), np.int32)
    weights = np.zeros((len(recs), 2), np.float32)
    outs = [cl.Buffer(ctx, mf.WRITE_ONLY, a.nbytes) for a in (zone, weights)]
    program.morph(queue, (len(recs),), None, source, np.int32(len(recs)), *outs)
    for host, buf in zip((zone, weights), outs):
        cl.enqueue_copy(queue, host, buf)
    sharpened = 0
    for k, f in enumerate(recs):
        shape, tip = sd2_shape(f)
        if shape != "sd2":
            assert zone[k] == -1, f
            continue
        inside, w, lam = sd2_morph(f, tip)
        assert zone[k] == int(inside), f
        if inside:
            assert weights[k].view(np.uint32).tolist() == np.array([w, lam], np.float32).view(np.uint32).tolist(), f
            sharpened += 0.0 < lam < 1.0
    assert sharpened > 50 and (zone == 1).sum() > 1000  # the zone and the steep part were drawn


def test_sharpening_keeps_the_ends_and_is_the_step_at_width_0():
    for lam in np.linspace(0, 1, 41, dtype=np.float32):
        assert _sharpen(lam, np.float32(1.0)) == lam  # width 1: lam itself
        assert _sharpen(lam, np.float32(0.0)) == (1.0 if lam >= 0.5 else 0.0)
        for kappa in (0.0, 0.01, 0.3, 1.0):
            out = _sharpen(lam, np.float32(kappa))
            assert 0.0 <= out <= 1.0
    for kappa in np.linspace(0, 1, 11, dtype=np.float32):
        assert _sharpen(np.float32(0.0), kappa) == 0.0 and _sharpen(np.float32(1.0), kappa) == 1.0


def test_switch_width():
    one = FIXED_ONE
    assert odd_distance(3 * one) == 0 and odd_distance(2 * one) == one and odd_distance(one // 2) == one // 2
    assert odd_distance(4 * one + one // 4) == 3 * one // 4
    assert _switch_width(3 * one, 3 * one) == 1.0  # the triple tie itself: lam's own width (lam is 1 there)
    assert _switch_width(2 * one, 2 * one - 5) == 1.0  # a triple tie at 2: lam's own width
    assert _switch_width(3 * one + 10, 3 * one - one // 8) == 1.0  # far from the triple tie (rho > the reach)
    assert _switch_width(3 * one + one // 8 + one // 64, 3 * one + one // 8) == 1.0  # an isolated triple tie at 3 1/8
    assert _switch_width(3 * one + one // 64, 3 * one) == np.float32(0.125)  # a plateau of 3 left by 1/64
    assert _switch_width(3 * one + one // 16, 3 * one) == np.float32(0.5)
