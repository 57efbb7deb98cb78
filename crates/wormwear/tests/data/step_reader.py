"""Reads a STEP file with OpenCASCADE (through gmsh's Python package) for tests/suite/cad.rs.

usage: step_reader.py FILE.step REQUEST.json  -> prints JSON on stdout

REQUEST: {"faces": [{"centroid": [x, y, z], "area": a}, ...],   (mm, mm^2: our faces to find)
          "points": [[x, y, z], ...],                               (mm: points to project)
          "point_faces": [[i, j, ...], ...]}                        (indices into faces, per point)
ANSWER:  {"solids": n, "volume": V, "areas": [OCC area of each requested face],
          "tetrahedra": number of tetrahedra gmsh fills the solid with (a closed, valid
                        boundary is needed for that; 0 if meshing failed),
          "centroid_gaps": [distance from our centroid to the matched OCC face's],
          "distances": [distance from each point to the nearest of its faces]}
The faces are matched by their centres of mass, which OpenCASCADE computes itself.
"""

import json
import math
import sys

import gmsh


def main():
    path, request_path = sys.argv[1], sys.argv[2]
    with open(request_path) as f:
        request = json.load(f)
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.occ.importShapes(path)
    gmsh.model.occ.synchronize()
    solids = gmsh.model.getEntities(3)
    volume = sum(gmsh.model.occ.getMass(3, tag) for _, tag in solids)
    surfaces = [tag for _, tag in gmsh.model.getEntities(2)]
    centres = {tag: gmsh.model.occ.getCenterOfMass(2, tag) for tag in surfaces}
    matched, areas, gaps = [], [], []
    for face in request["faces"]:
        c = face["centroid"]
        tag = min(surfaces, key=lambda t: math.dist(centres[t], c))
        matched.append(tag)
        areas.append(gmsh.model.occ.getMass(2, tag))
        gaps.append(math.dist(centres[tag], c))
    distances = []
    for point, faces in zip(request["points"], request["point_faces"]):
        best = math.inf
        for i in faces:
            closest, _ = gmsh.model.getClosestPoint(2, matched[i], point)
            best = min(best, math.dist(closest, point))
        distances.append(best)
    tetrahedra = 0
    try:
        # Coarse tetrahedra (2-10 mm): any volume mesh needs a closed, valid boundary, which
        # is what is checked; 6 mm elements took 15 s more for the same answer.
        gmsh.option.setNumber("Mesh.MeshSizeMin", 2.0)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 10.0)
        gmsh.model.mesh.generate(3)
        _, elements, _ = gmsh.model.mesh.getElements(3)
        tetrahedra = sum(len(e) for e in elements)
    except Exception as e:  # noqa: BLE001 (any failure is the answer 0)
        print(f"meshing failed: {e}", file=sys.stderr)
    gmsh.finalize()
    json.dump(
        {
            "solids": len(solids),
            "tetrahedra": tetrahedra,
            "volume": volume,
            "areas": areas,
            "centroid_gaps": gaps,
            "distances": distances,
        },
        sys.stdout,
    )


if __name__ == "__main__":
    main()
