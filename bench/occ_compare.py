"""cltess against OpenCASCADE's BRepMesh: triangles at equal *measured* deviation.

Run in a separate virtual environment that has OpenCASCADE (package ``cadquery-ocp``, kept out of
cltess's dependencies) besides cltess itself:

    python3 -m venv /work/venv-occ
    /work/venv-occ/bin/pip install cadquery-ocp numpy trimesh "pyopencl[pocl]" mako -e .
    /work/venv-occ/bin/python bench/occ_compare.py --json bench/results/occ_compare.json

Scenes: the exact rational torus (scenes/torus.bpt), 20 random rational patches (weights 0.2 to
5, the recipe of tests/support.random_patches, seed 1) and the teapot (polynomial).  cltess runs at
several eps, OpenCASCADE's BRepMesh_IncrementalMesh at linear deflections from 1e-1 of the
diagonal down by sqrt(10) at a time until its measured deviation is below cltess's smallest
(or 2 million triangles; angular deflection 0.5 rad, its default, and 1.5 rad, nearly off), each patch one face of a
compound.

Every mesh is measured the same way, independently of both programs' own estimates: densely
inside every triangle (barycentric samples of order 6, edges included) the distance between the
mesh, interpolated linearly, and the float64 surface at the interpolated (u, v) of the
triangle's vertices (OpenCASCADE's UV nodes; cltess's vertex uv).  Triangle counts at equal
measured deviation: each cltess point against OpenCASCADE's Pareto front (its fewest triangles
for at most that deviation, over both angular settings), interpolated log-log.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "scenes"
RELATIVE_EPS = [3e-2, 1e-2, 3e-3, 1e-3]  # of the bounding-box diagonal
LARGEST_DEFLECTION = 1e-1  # of the diagonal; then / sqrt(10) at a time, until OCC's measured
MAX_OCC_RUNS = 12          # deviation is below cltess's smallest (or this many runs per angle,
MAX_OCC_TRIANGLES = 2_000_000  # or this many triangles)
ANGLES = [0.5, 1.5]


# --- scenes -----------------------------------------------------------------------------------

def random_rational_patches(count: int = 20, seed: int = 1) -> np.ndarray:
    """tests/support.random_patches: points near a 4 x 4 grid (step 0.3, noise 0.3), scattered
    in a box (spread 5), weights uniform in [0.2, 5]."""
    rng = np.random.default_rng(seed)
    points = rng.normal(size=(count, 4, 4, 3)) * 0.3 + rng.normal(size=(count, 1, 1, 3)) * 5.0
    points += np.stack(np.meshgrid(np.arange(4), np.arange(4), [0], indexing="xy"), -1)[:, :, 0] * 0.3
    weights = rng.uniform(0.2, 5.0, size=(count, 4, 4))
    return np.concatenate([points * weights[..., None], weights[..., None]], axis=-1)


def load_patches(name: str) -> np.ndarray:
    from cltess.io import load_scene

    if name == "random":
        return random_rational_patches()
    return load_scene(SCENES / {"torus": "torus.bpt", "teapot": "teapot.bez", "sphere": "sphere.bpt"}[name]).patches


def diagonal(patches: np.ndarray) -> float:
    points = (patches[..., :3] / patches[..., 3:]).reshape(-1, 3)
    return float(np.linalg.norm(points.max(0) - points.min(0)))


# --- the independent measure --------------------------------------------------------------------

def bernstein3(t: np.ndarray) -> np.ndarray:
    s = 1 - t
    return np.stack([s ** 3, 3 * t * s * s, 3 * t * t * s, t ** 3], axis=-1)


def measured_deviation(patches, positions, uv, patch_of_triangle, triangles, order: int = 6) -> float:
    """Largest |S(u, v) - mesh(u, v)| over barycentric samples of every triangle (float64)."""
    ij = [(i, j) for i in range(order + 1) for j in range(order + 1 - i)]
    bary = np.array([(i, j, order - i - j) for i, j in ij], float) / order
    positions, uv = np.asarray(positions, float), np.asarray(uv, float)
    worst = 0.0
    for p in np.unique(patch_of_triangle):
        tris = triangles[patch_of_triangle == p]
        for start in range(0, len(tris), 20000):
            t = tris[start:start + 20000]
            mesh = np.einsum("sk,tkc->tsc", bary, positions[t]).reshape(-1, 3)
            at = np.einsum("sk,tkc->tsc", bary, uv[t]).reshape(-1, 2)
            h = np.einsum("nj,ni,jic->nc", bernstein3(at[:, 1]), bernstein3(at[:, 0]), patches[p])
            worst = max(worst, float(np.linalg.norm(h[:, :3] / h[:, 3:] - mesh, axis=1).max()))
    return worst


# --- cltess ---------------------------------------------------------------------------------------

def run_cltess(patches: np.ndarray, eps: float, bound: str = "hull") -> dict:
    from cltess.pipeline import Tessellator
    from cltess.scene import Scene

    tessellator = run_cltess.__dict__.setdefault("tessellator", Tessellator())
    scene = Scene(patches, np.zeros(len(patches), np.int32), name="bench")
    start = time.perf_counter()
    tess = tessellator.tessellate(scene, eps=eps, max_factor=4096, bound=bound)
    seconds = time.perf_counter() - start
    tris = tess.triangles.astype(np.int64)
    deviation = measured_deviation(patches, tess.positions, tess.uv, tess.patch_ids[tris[:, 0]], tris)
    return {"eps": eps, "triangles": int(len(tris)), "deviation": deviation, "seconds": seconds,
            "saturated": int(tess.stats["saturated"])}


# --- OpenCASCADE ----------------------------------------------------------------------------------

def occ_faces(patches: np.ndarray):
    """One face per patch, on a Geom_BezierSurface with poles(i+1, j+1) = P[j, i] (u first)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.Geom import Geom_BezierSurface
    from OCP.gp import gp_Pnt
    try:  # OCP 7.x: TColgp / TColStd; OCP 8: the NCollection templates in OCP.collections
        from OCP.TColgp import TColgp_Array2OfPnt as PointArray
        from OCP.TColStd import TColStd_Array2OfReal as RealArray
    except ImportError:
        from OCP.collections import Array2_double as RealArray, Array2_gp_Pnt as PointArray

    faces = []
    for patch in patches:
        poles, weights = PointArray(1, 4, 1, 4), RealArray(1, 4, 1, 4)
        for j in range(4):
            for i in range(4):
                w = float(patch[j, i, 3])
                poles.SetValue(i + 1, j + 1, gp_Pnt(*(float(x) / w for x in patch[j, i, :3])))
                weights.SetValue(i + 1, j + 1, w)
        rational = not (patch[..., 3] == patch[0, 0, 3]).all()
        surface = Geom_BezierSurface(poles, weights) if rational else Geom_BezierSurface(poles)
        faces.append(BRepBuilderAPI_MakeFace(surface, 1e-9).Face())
    return faces


def run_occ(patches: np.ndarray, deflection: float, angle: float) -> dict:
    from OCP.BRep import BRep_Builder, BRep_Tool
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS_Compound

    faces = occ_faces(patches)  # fresh faces: no triangulation left from an earlier run
    builder, compound = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(compound)
    for face in faces:
        builder.Add(compound, face)
    start = time.perf_counter()
    BRepMesh_IncrementalMesh(compound, deflection, False, angle, True)
    seconds = time.perf_counter() - start
    positions, uv, owner, triangles = [], [], [], []
    base = 0
    for p, face in enumerate(faces):
        tri = BRep_Tool.Triangulation_s(face, TopLoc_Location())
        nodes = range(1, tri.NbNodes() + 1)
        positions += [tri.Node(k).Coord() for k in nodes]
        uv += [tri.UVNode(k).Coord() for k in nodes]
        triangles += [[base + k - 1 for k in tri.Triangle(t).Get()] for t in range(1, tri.NbTriangles() + 1)]
        owner += [p] * tri.NbTriangles()
        base += tri.NbNodes()
    triangles = np.array(triangles, np.int64)
    deviation = measured_deviation(patches, np.array(positions), np.array(uv), np.array(owner), triangles)
    return {"deflection": deflection, "angle": angle, "triangles": int(len(triangles)),
            "deviation": deviation, "seconds": seconds}


# --- comparison -----------------------------------------------------------------------------------

def pareto(points: list[dict]) -> list[tuple[float, float]]:
    """(deviation, triangles) of the runs no other run beats on both, by deviation."""
    pts = sorted((r["deviation"], r["triangles"]) for r in points)
    front = []
    for d, t in pts:
        if not front or t < front[-1][1]:
            front.append((d, t))
    return front


def triangles_at(front: list[tuple[float, float]], deviation: float) -> float | None:
    """Fewest triangles for a measured deviation of ``deviation`` on a front, log-log
    interpolated between its points; None outside its range."""
    for (d0, t0), (d1, t1) in zip(front, front[1:]):
        if d0 <= deviation <= d1:
            a = (math.log(deviation) - math.log(d0)) / (math.log(d1) - math.log(d0))
            return math.exp((1 - a) * math.log(t0) + a * math.log(t1))
    return None


def print_cltess_rows(label: str, rows: list[dict], front, size: float) -> None:
    for r in rows:
        occ = triangles_at(front, r["deviation"])
        ratio = f"{r['triangles'] / occ:.2f}" if occ else "n/a"
        print(f"| {label} | {r['eps'] / size:.0e} | {r['triangles']} | {r['deviation'] / r['eps']:.3f} | "
              f"{r['deviation'] / size:.2e} | {f'{occ:.0f}' if occ else 'n/a'} | {ratio} |")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scenes", nargs="+", default=["torus", "random", "teapot", "sphere"])
    parser.add_argument("--json", type=Path, help="write every run here")
    parser.add_argument("--no-occ", action="store_true", help="cltess only (e.g. to compare two versions)")
    parser.add_argument("--baseline", type=Path, help="a --json of another cltess version: its rows too")
    parser.add_argument("--baseline-label", default="baseline")
    parser.add_argument("--bound", choices=("hull", "integral", "error-hull"), default="hull",
                        help="cltess's Request.bound (integral, error-hull: docs/rational-bound.md)")
    args = parser.parse_args(argv)
    baseline = json.loads(args.baseline.read_text()) if args.baseline else None

    import cltess

    results = {"cltess": str(Path(cltess.__file__).parent), "scenes": {}}
    for name in args.scenes:
        patches = load_patches(name)
        size = diagonal(patches)
        runs = {"diagonal": size, "cltess": [run_cltess(patches, e * size, args.bound) for e in RELATIVE_EPS], "occ": []}
        rows = runs["cltess"] + (baseline["scenes"].get(name, {}).get("cltess", []) if baseline else [])
        target = min(r["deviation"] for r in rows)
        for angle in ANGLES if not args.no_occ else []:
            for k in range(MAX_OCC_RUNS):
                runs["occ"].append(run_occ(patches, LARGEST_DEFLECTION * size / 10 ** (k / 2), angle))
                if runs["occ"][-1]["deviation"] < target or runs["occ"][-1]["triangles"] > MAX_OCC_TRIANGLES:
                    break
        results["scenes"][name] = runs
        front = pareto(runs["occ"])
        print(f"\n### {name} ({len(patches)} patches, diagonal {size:.3g})\n")
        print("| cltess | eps / diag | triangles | measured dev / eps | measured dev / diag "
              "| OCC triangles at that dev | cltess / OCC |")
        print("|---|---|---|---|---|---|---|")
        print_cltess_rows("this", runs["cltess"], front, size)
        if baseline and name in baseline["scenes"]:
            print_cltess_rows(args.baseline_label, baseline["scenes"][name]["cltess"], front, size)
        if runs["occ"]:
            print("\n| OCC deflection / diag | angle | triangles | measured dev / deflection | measured dev / diag |")
            print("|---|---|---|---|---|")
            for r in runs["occ"]:
                print(f"| {r['deflection'] / size:.1e} | {r['angle']} | {r['triangles']} | "
                      f"{r['deviation'] / r['deflection']:.2f} | {r['deviation'] / size:.2e} |")
        sys.stdout.flush()
    if args.json:
        args.json.write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
