"""Regenerate the Gmsh test meshes of this folder (MSH 4.1 ASCII).

Run from this folder with the Gmsh Python API (`pip install gmsh`):

    python3 make_meshes.py

Meshes (every one with named physical groups):
- rectangle_tri3.msh: unstructured triangles of [0, 2] x [0, 1];
  curves "y0", "x1", "y1", "x0", surface "domain".
- annulus_tri3.msh: unstructured triangles of the annulus 0.75 <= r <= 1.25
  (the elastic annulus case); curves "inner", "outer", surface "domain".
- rectangle_tri6.msh: the rectangle with six-node triangles (patch parents).
- box_tet10.msh: ten-node tetrahedra of [0, 1] x [0, 1] x [0, 2];
  surfaces "x0", "x1", "y0", "y1", "z0", "z1", volume "solid".
"""

import gmsh


def start(name):
    gmsh.model.add(name)
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)


def rectangle(order, size, path):
    start(path)
    occ = gmsh.model.occ
    surface = occ.addRectangle(0.0, 0.0, 0.0, 2.0, 1.0)
    occ.synchronize()
    curves = [tag for (_, tag) in gmsh.model.getBoundary([(2, surface)])]
    for tag in curves:
        x0, y0, _, x1, y1, _ = gmsh.model.getBoundingBox(1, tag)
        if abs(y1 - y0) < 1e-6:
            name = "y0" if y0 < 0.5 else "y1"
        else:
            name = "x0" if x0 < 1.0 else "x1"
        gmsh.model.addPhysicalGroup(1, [tag], name=name)
    gmsh.model.addPhysicalGroup(2, [surface], name="domain")
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.generate(2)
    gmsh.model.mesh.setOrder(order)
    gmsh.write(path)
    gmsh.model.remove()


def annulus(size, path):
    start(path)
    occ = gmsh.model.occ
    outer = occ.addDisk(0.0, 0.0, 0.0, 1.25, 1.25)
    inner = occ.addDisk(0.0, 0.0, 0.0, 0.75, 0.75)
    ring, _ = occ.cut([(2, outer)], [(2, inner)])
    occ.synchronize()
    surface = ring[0][1]
    for (_, tag) in gmsh.model.getBoundary([(2, surface)]):
        x0, _, _, x1, _, _ = gmsh.model.getBoundingBox(1, tag)
        name = "outer" if x1 - x0 > 2.0 else "inner"
        gmsh.model.addPhysicalGroup(1, [tag], name=name)
    gmsh.model.addPhysicalGroup(2, [surface], name="domain")
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.generate(2)
    gmsh.write(path)
    gmsh.model.remove()


def box(size, path):
    start(path)
    occ = gmsh.model.occ
    volume = occ.addBox(0.0, 0.0, 0.0, 1.0, 1.0, 2.0)
    occ.synchronize()
    upper = [1.0, 1.0, 2.0]
    for (_, tag) in gmsh.model.getBoundary([(3, volume)]):
        lo = gmsh.model.getBoundingBox(2, tag)
        for axis in range(3):
            if abs(lo[axis + 3] - lo[axis]) < 1e-6:
                side = "0" if lo[axis] < 0.5 * upper[axis] else "1"
                gmsh.model.addPhysicalGroup(2, [tag], name="xyz"[axis] + side)
    gmsh.model.addPhysicalGroup(3, [volume], name="solid")
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(2)
    gmsh.write(path)
    gmsh.model.remove()


gmsh.initialize()
rectangle(1, 0.2, "rectangle_tri3.msh")
annulus(0.1, "annulus_tri3.msh")
rectangle(2, 0.4, "rectangle_tri6.msh")
box(0.5, "box_tet10.msh")
gmsh.finalize()
