"""pdamp dem's ParaView files read by VTK's own reader (python3-vtk9).

Runs `pdamp dem` on a softened copy of the shipped low-intensity case with --snapshots 3,
then reads particles.pvd (a ParaView collection) and each particles_NNNN.vtp with
vtkXMLPolyDataReader: one vertex per particle, the radius, velocity, spin and compartment
arrays, the times of the series equal to each file's TimeValue and increasing.
Usage: check_paraview_series.py PDAMP_BINARY SOURCE_DIR WORK_DIR
"""
import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ElementTree

import vtk
from vtk.util.numpy_support import vtk_to_numpy


def main():
    pdamp, source, work = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    with open(os.path.join(source, "cases", "low_intensity_36_spheres.json")) as f:
        case = json.load(f)
    # Soft contacts and one analysed period: the files, not the physics, are under test.
    case["dem"] = {"stiffness_softening": 1e-3, "transient_periods": 0, "analysed_periods": 1}
    case_path = os.path.join(work, "case.json")
    with open(case_path, "w") as f:
        json.dump(case, f)
    out = os.path.join(work, "out")
    subprocess.run([pdamp, "dem", case_path, "--snapshots", "3", "-o", out, "--overwrite", "--json"],
                   check=True, stdout=subprocess.DEVNULL)

    series = ElementTree.parse(os.path.join(out, "particles.pvd")).getroot()
    assert series.get("type") == "Collection", series.get("type")
    datasets = series.find("Collection").findall("DataSet")
    assert len(datasets) == 3, len(datasets)
    times = [float(d.get("timestep")) for d in datasets]
    assert times == sorted(times) and len(set(times)) == 3, times
    count = case["damper"]["particles"]["count"]
    radius = case["damper"]["particles"]["radius_m"]
    for dataset, time in zip(datasets, times):
        reader = vtk.vtkXMLPolyDataReader()
        reader.SetFileName(os.path.join(out, dataset.get("file")))
        reader.Update()
        assert reader.GetErrorCode() == 0, dataset.get("file")
        data = reader.GetOutput()
        assert data.GetNumberOfPoints() == count, data.GetNumberOfPoints()
        assert data.GetNumberOfVerts() == count, data.GetNumberOfVerts()
        points = data.GetPointData()
        radii = vtk_to_numpy(points.GetArray("radius_m"))
        assert abs(radii.mean() - radius) < 0.01 * radius, radii.mean()  # the case's radius, within its spread
        for name, components in (("velocity_m_s", 3), ("angular_velocity_rad_s", 3), ("compartment", 1)):
            array = points.GetArray(name)
            assert array is not None, name
            assert array.GetNumberOfComponents() == components, name
            assert array.GetNumberOfTuples() == count, name
        field = vtk_to_numpy(data.GetFieldData().GetArray("TimeValue"))
        assert abs(field[0] - time) <= 1e-12 * max(1.0, time), (field[0], time)
        speeds = vtk_to_numpy(points.GetArray("velocity_m_s"))
        assert speeds.shape == (count, 3)
    print("ParaView series: %d snapshots of %d particles read by VTK %s" % (len(datasets), count, vtk.vtkVersion.GetVTKVersion()))


if __name__ == "__main__":
    main()
