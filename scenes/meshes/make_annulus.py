"""Regenerate the unstructured annulus meshes of the elastic annulus case
(Coombs et al. 2020 §7.4): linear triangles of 0.75 <= r <= 1.25 with the
paper's five element sizes, MSH 4.1 ASCII, physical curves "inner" and
"outer" (the rims) and surface "domain".

Run from this folder with the Gmsh Python API (`pip install gmsh`, tested
with Gmsh 4.15.2):

    python3 make_annulus.py
"""

import gmsh

SIZES = [0.4363, 0.2182, 0.1091, 0.0545, 0.0273]


def annulus(size, path):
    gmsh.initialize()
    gmsh.model.add(path)
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
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
    gmsh.option.setNumber("Mesh.MeshSizeMin", size)
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.generate(2)
    gmsh.write(path)
    gmsh.finalize()


for i, h in enumerate(SIZES):
    annulus(h, "annulus_%d.msh" % i)
