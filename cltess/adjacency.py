"""Re-exports for one release: edge groups are ``cltess.crack.adjacency``, the mesh edges and
sharp-edge modes ``cltess.kinds.pn``."""
from .crack.adjacency import EdgeGroups, edge_groups, merge_edge_groups
from .kinds.pn import SHARP_EDGE_MODES, mesh_edge_groups, pn_edge_normals

__all__ = ["EdgeGroups", "edge_groups", "mesh_edge_groups", "pn_edge_normals", "merge_edge_groups",
           "SHARP_EDGE_MODES"]
