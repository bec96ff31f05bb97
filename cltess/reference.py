"""The NumPy reference of every pipeline stage, gathered for tests and benchmarks (float64, slow,
obviously right).  It lives by what varies: surfaces per kind (cltess.surfaces), criteria
(cltess.criteria), patterns (cltess.patterns), the crack policy (cltess.crack.adjacency) and the
NumPy backend (cltess.backends.numpy); the engine imports none of it from here."""
from .backends.numpy import counts, offsets, pn_tessellate, tessellate
from .crack.adjacency import crack_free_factors
from .criteria.base import DEFAULT_MAX_FACTOR
from .criteria.filip import (pn_factor_tolerances, pn_factors, pn_inverse_steps, pn_second_derivative_bounds,
                             pn_tolerances)
from .criteria.tolerance import box_tolerances, patch_factor_tolerances, patch_tolerances
from .criteria.zheng_sederberg import (diagonal_majorant, second_derivative_bounds, second_derivative_hull, zs_factors,
                                       zs_inverse_steps, zs_steps)
from .patterns import quad_pattern, tri_pattern
from .scene import boundary_curves
from .surfaces.bezier import (NORMAL_DEGENERATE, NORMAL_SHIFT, bernstein2, bernstein3, bernstein3_derivative,
                              boundary_point, evaluate, homogeneous_and_derivatives, limit_normal, surface_points)
from .surfaces.pn import (CUBIC, EDGE_DIRECTIONS, PN_NORMAL_VANISHES, QUADRATIC, pn_control_points,
                          pn_edge_control, pn_evaluate, pn_folded, pn_surface_points)

__all__ = ["patch_tolerances", "patch_factor_tolerances", "pn_factor_tolerances", "box_tolerances", "zs_factors", "zs_inverse_steps", "zs_steps", "second_derivative_bounds",
           "second_derivative_hull", "diagonal_majorant", "crack_free_factors",
           "quad_pattern", "counts", "offsets", "evaluate", "surface_points", "tessellate", "boundary_point",
           "boundary_curves", "pn_control_points", "pn_edge_control", "pn_second_derivative_bounds",
           "pn_inverse_steps", "pn_tolerances", "pn_factors", "pn_folded", "tri_pattern", "pn_evaluate",
           "pn_surface_points", "pn_tessellate", "DEFAULT_MAX_FACTOR", "NORMAL_SHIFT", "NORMAL_DEGENERATE",
           "PN_NORMAL_VANISHES", "CUBIC", "QUADRATIC", "EDGE_DIRECTIONS", "bernstein2", "bernstein3",
           "bernstein3_derivative", "homogeneous_and_derivatives", "limit_normal"]
