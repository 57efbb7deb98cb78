"""Two STEP solids as OpenCASCADE (gmsh) sees them together, for tests/suite/cad.rs.

usage: step_assembly.py A.step B.step  -> prints JSON on stdout:
  {"intersection": volume common to both (mm^3), "distance": least distance between them (mm)}
"""

import json
import sys

import gmsh


def main():
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    a = gmsh.model.occ.importShapes(sys.argv[1])
    b = gmsh.model.occ.importShapes(sys.argv[2])
    gmsh.model.occ.synchronize()
    distance = gmsh.model.occ.getDistance(3, a[0][1], 3, b[0][1])[0]
    common, _ = gmsh.model.occ.intersect(a, b, removeObject=False, removeTool=False)
    gmsh.model.occ.synchronize()
    volume = sum(gmsh.model.occ.getMass(3, tag) for dim, tag in common if dim == 3)
    gmsh.finalize()
    json.dump({"intersection": volume, "distance": distance}, sys.stdout)


if __name__ == "__main__":
    main()
