"""Regenerate cube_tet10.msh: an unstructured mesh of ten-node tetrahedra
(F-patch parents, split into eight linear children when read) of the 2 m
cube of the simple stretch case (Wang et al. 2021 §5.3), MSH 4.1 ASCII,
with physical surfaces "x0", "x1", "y0", "y1", "z0", "z1" and volume
"solid".

Run from this folder with the Gmsh Python API (`pip install gmsh`, tested
with Gmsh 4.15.2):

    python3 make_cube.py
"""

import gmsh

gmsh.initialize()
gmsh.model.add("cube")
gmsh.option.setNumber("General.Terminal", 0)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.option.setNumber("Mesh.Binary", 0)
gmsh.option.setNumber("Mesh.RandomSeed", 1)
volume = gmsh.model.occ.addBox(0.0, 0.0, 0.0, 2.0, 2.0, 2.0)
gmsh.model.occ.synchronize()
for (_, tag) in gmsh.model.getBoundary([(3, volume)], oriented=False):
    box = gmsh.model.getBoundingBox(2, tag)
    for axis, name in enumerate("xyz"):
        if abs(box[axis + 3] - box[axis]) < 1e-3:
            side = 0 if box[axis] < 1.0 else 1
            gmsh.model.addPhysicalGroup(2, [tag], name=f"{name}{side}")
gmsh.model.addPhysicalGroup(3, [volume], name="solid")
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.7)
gmsh.model.mesh.generate(3)
gmsh.model.mesh.setOrder(2)
gmsh.write("cube_tet10.msh")
gmsh.finalize()
