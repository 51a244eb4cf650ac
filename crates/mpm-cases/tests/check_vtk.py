"""Reads the files written by the ignored test `vtk_python` with VTK's own
XML reader (the one ParaView uses for .vtu) and checks them against the
manifest `expected.json` that the test wrote beside them.

Usage: python check_vtk.py DIR   (needs `pip install vtk`; exits non-zero on
any mismatch or reader error/warning).
"""

import json
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

from vtkmodules.vtkCommonCore import vtkCommand
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader


def read_vtu(path):
    problems = []
    reader = vtkXMLUnstructuredGridReader()
    for event in (vtkCommand.ErrorEvent, vtkCommand.WarningEvent):
        reader.AddObserver(event, lambda obj, ev, calldata=None: problems.append(ev))
    reader.SetFileName(str(path))
    reader.Update()
    if problems or reader.GetErrorCode() != 0:
        raise SystemExit(f"{path}: VTK reader reported {problems or reader.GetErrorCode()}")
    return reader.GetOutput()


def check_arrays(path, data, expected, what):
    for name, (components, values) in expected.items():
        array = data.GetArray(name)
        if array is None:
            raise SystemExit(f"{path}: no {what} array {name!r}")
        if array.GetNumberOfComponents() != components:
            raise SystemExit(f"{path}: {name} has {array.GetNumberOfComponents()} components, expected {components}")
        got = [array.GetComponent(i // components, i % components) for i in range(len(values))]
        if got != values:
            raise SystemExit(f"{path}: {name} = {got}, expected {values}")


def main(directory):
    directory = Path(directory)
    manifest = json.loads((directory / "expected.json").read_text())
    for name, expected in manifest["grids"].items():
        path = directory / name
        grid = read_vtu(path)
        if grid.GetNumberOfPoints() != expected["n_points"]:
            raise SystemExit(f"{path}: {grid.GetNumberOfPoints()} points, expected {expected['n_points']}")
        if grid.GetNumberOfCells() != expected["n_cells"]:
            raise SystemExit(f"{path}: {grid.GetNumberOfCells()} cells, expected {expected['n_cells']}")
        types = [grid.GetCellType(i) for i in range(grid.GetNumberOfCells())]
        if types != expected["cell_types"]:
            raise SystemExit(f"{path}: cell types {types}, expected {expected['cell_types']}")
        sizes = [grid.GetCell(i).GetNumberOfPoints() for i in range(grid.GetNumberOfCells())]
        if sizes != expected["cell_sizes"]:
            raise SystemExit(f"{path}: cell sizes {sizes}, expected {expected['cell_sizes']}")
        points = [c for i in range(grid.GetNumberOfPoints()) for c in grid.GetPoint(i)]
        if points != expected["points"]:
            raise SystemExit(f"{path}: points {points}, expected {expected['points']}")
        check_arrays(path, grid.GetPointData(), expected["point_data"], "point")
        check_arrays(path, grid.GetCellData(), expected["cell_data"], "cell")
        print(f"ok {path.name}: {len(types)} cells, arrays read by VTK")

    # The .pvd: well-formed, and every data set it lists is readable.
    pvd = directory / manifest["pvd"]
    datasets = ET.parse(pvd).getroot().findall("./Collection/DataSet")
    times = [float(d.get("timestep")) for d in datasets]
    if times != manifest["pvd_times"]:
        raise SystemExit(f"{pvd}: times {times}, expected {manifest['pvd_times']}")
    for d in datasets:
        read_vtu(pvd.parent / d.get("file"))
    print(f"ok {pvd.name}: {len(datasets)} steps, each readable")


if __name__ == "__main__":
    main(sys.argv[1])
