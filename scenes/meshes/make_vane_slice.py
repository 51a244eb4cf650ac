"""Regenerate the meshes of the vane slice of Wang et al. 2021 §5.5: a
cylinder of soil (radius 3 r_v, height r_v, r_v = 0.05 m) around a
four-bladed vane (blades of radius r_v and thickness 0.1 r_v through the
whole height) or, for a test with a closed-form answer, a solid cylinder of
radius r_v, ten-node tetrahedra (the F-patch parents, split into eight
linear children when read), MSH 4.1 ASCII. Physical groups: surfaces
"vane" (every blade face), "outer" (the cylinder), "top" and "bottom";
volume "soil". The mesh is finest along the blades and grows towards the
outer surface.

Run from this folder with the Gmsh Python API (`pip install gmsh`, tested
with Gmsh 4.15.2):

    python3 make_vane_slice.py
"""

import gmsh

RV = 0.05
HEIGHT = RV
THICK = 0.1 * RV
OUTER = 3 * RV

# name: (core, element size at the core, element size at the outer surface)
MESHES = {
    # 95,456 linear tetrahedra in the paper; about 11,900 parents here.
    "vane_slice.msh": ("vane", 1.15 * THICK, 0.44 * RV),
    # A coarse mesh for the tests and the quick reproduction.
    "vane_slice_quick.msh": ("vane", 3 * THICK, 1.2 * RV),
    # The vane replaced by a solid cylinder of radius r_v: the elastic
    # torque has a closed form (a test of the rotating mesh and the torque).
    "cylinder_slice_test.msh": ("cylinder", 0.4 * RV, 0.5 * RV),
}


def build(name, core, fine, coarse):
    gmsh.initialize()
    gmsh.model.add("vane_slice")
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
    occ = gmsh.model.occ
    soil = occ.addCylinder(0, 0, 0, 0, 0, HEIGHT, OUTER)
    if core == "vane":
        a = occ.addBox(-RV, -THICK / 2, 0, 2 * RV, THICK, HEIGHT)
        b = occ.addBox(-THICK / 2, -RV, 0, THICK, 2 * RV, HEIGHT)
        vane, _ = occ.fuse([(3, a)], [(3, b)])
    else:
        vane = [(3, occ.addCylinder(0, 0, 0, 0, 0, HEIGHT, RV))]
    cut, _ = occ.cut([(3, soil)], vane)
    occ.synchronize()
    volume = cut[0][1]
    groups = {"vane": [], "outer": [], "top": [], "bottom": []}
    for _, tag in gmsh.model.getBoundary([(3, volume)], oriented=False):
        x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(2, tag)
        if abs(z1 - z0) < 1e-6:  # OCC pads bounding boxes by 1e-7
            groups["top" if z0 > HEIGHT / 2 else "bottom"].append(tag)
        elif max(abs(x0), abs(x1), abs(y0), abs(y1)) > 2 * RV:
            groups["outer"].append(tag)
        else:
            groups["vane"].append(tag)
    for group, tags in groups.items():
        gmsh.model.addPhysicalGroup(2, tags, name=group)
    gmsh.model.addPhysicalGroup(3, [volume], name="soil")
    distance = gmsh.model.mesh.field.add("Distance")
    gmsh.model.mesh.field.setNumbers(distance, "SurfacesList", groups["vane"])
    threshold = gmsh.model.mesh.field.add("Threshold")
    gmsh.model.mesh.field.setNumber(threshold, "InField", distance)
    gmsh.model.mesh.field.setNumber(threshold, "SizeMin", fine)
    gmsh.model.mesh.field.setNumber(threshold, "SizeMax", coarse)
    gmsh.model.mesh.field.setNumber(threshold, "DistMin", 0.0)
    gmsh.model.mesh.field.setNumber(threshold, "DistMax", OUTER - RV)
    gmsh.model.mesh.field.setAsBackgroundMesh(threshold)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(2)
    types, tags, _ = gmsh.model.mesh.getElements(3)
    parents = sum(len(t) for t in tags)
    nodes = len(gmsh.model.mesh.getNodes()[0])
    print(f"{name}: {parents} ten-node tetrahedra ({8 * parents} children), {nodes} nodes")
    gmsh.write(name)
    gmsh.finalize()


for name, (core, fine, coarse) in MESHES.items():
    build(name, core, fine, coarse)
