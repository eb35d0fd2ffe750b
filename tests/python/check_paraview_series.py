"""pdamp dem's ParaView files read by VTK's own reader (python3-vtk9).

Runs `pdamp dem` on a softened copy of the shipped low-intensity case with --snapshots 3,
then reads particles.pvd (a ParaView collection) and each particles_NNNN.vtp with
vtkXMLPolyDataReader: one vertex per particle, the radius, velocity, spin and compartment
arrays, the times of the series equal to each file's TimeValue and increasing; and
container.pvd: the box's six faces at the same times, its size the case's, displaced along
the drive by the recorded container position. Then the same for a DEM-in-the-loop decay
(pdamp decay --method dem --snapshots 4): each bed's series, its spheres inside its box.
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
        for name, components in (("velocity_m_s", 3), ("angular_velocity_rad_s", 3), ("compartment", 1), ("contacts", 1)):
            array = points.GetArray(name)
            assert array is not None, name
            assert array.GetNumberOfComponents() == components, name
            assert array.GetNumberOfTuples() == count, name
        field = vtk_to_numpy(data.GetFieldData().GetArray("TimeValue"))
        assert abs(field[0] - time) <= 1e-12 * max(1.0, time), (field[0], time)
        contacts = vtk_to_numpy(points.GetArray("contacts"))
        assert (contacts >= 0).all() and contacts.max() >= 1, contacts  # a bed in a box touches it somewhere
        speeds = vtk_to_numpy(points.GetArray("velocity_m_s"))
        assert speeds.shape == (count, 3)
    # The container at the same times: the 160 x 61 x 40 mm box's six inner faces, moved
    # along the drive (x) by the recorded container position at each snapshot.
    containers = ElementTree.parse(os.path.join(out, "container.pvd")).getroot().find("Collection").findall("DataSet")
    assert [float(d.get("timestep")) for d in containers] == times
    size = case["damper"]["container"]["inner_size_m"]
    with open(os.path.join(out, "time_series.csv")) as f:
        header = f.readline().strip().split(",")
        rows = [[float(x) for x in line.split(",")] for line in f if line.strip()]
    column = header.index("container_position_m")
    for dataset, time in zip(containers, times):
        reader = vtk.vtkXMLPolyDataReader()
        reader.SetFileName(os.path.join(out, dataset.get("file")))
        reader.Update()
        data = reader.GetOutput()
        assert data.GetNumberOfPolys() == 6, data.GetNumberOfPolys()
        bounds = data.GetBounds()  # xmin, xmax, ymin, ymax, zmin, zmax
        for axis in range(3):
            assert abs((bounds[2 * axis + 1] - bounds[2 * axis]) - size[axis]) < 1e-12, (axis, bounds)
        # The box's centre is its rest centre (0) plus the container's displacement, which
        # lies between the two recorded samples around the snapshot's time.
        centre = 0.5 * (bounds[0] + bounds[1])
        before = max((r for r in rows if r[0] <= time), key=lambda r: r[0], default=rows[0])
        after = min((r for r in rows if r[0] >= time), key=lambda r: r[0], default=rows[-1])
        low, high = sorted((before[column], after[column]))
        assert low - 1e-12 <= centre <= high + 1e-12, (centre, low, high)
        assert abs(0.5 * (bounds[2] + bounds[3])) < 1e-12 and abs(0.5 * (bounds[4] + bounds[5])) < 1e-12
        part = vtk_to_numpy(data.GetCellData().GetArray("part"))
        assert (part == 0).all()
        # Same frame as the particles: every sphere is inside the box at that instant (its
        # centre at least a radius from each face, less the contact overlap, < 10 % of r).
        spheres = vtk.vtkXMLPolyDataReader()
        spheres.SetFileName(os.path.join(out, dataset.get("file").replace("container", "particles")))
        spheres.Update()
        centres = vtk_to_numpy(spheres.GetOutput().GetPoints().GetData())
        for axis in range(3):
            assert (centres[:, axis] >= bounds[2 * axis] + 0.9 * radius).all(), axis
            assert (centres[:, axis] <= bounds[2 * axis + 1] - 0.9 * radius).all(), axis
    decay_snapshots = check_decay_series(pdamp, source, work)
    print("ParaView series: %d snapshots of %d particles and the container, and %d of a DEM-in-the-loop decay, "
          "read by VTK %s" % (len(datasets), count, decay_snapshots, vtk.vtkVersion.GetVTKVersion()))


def read_polydata(path):
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    assert reader.GetErrorCode() == 0, path
    return reader.GetOutput()


def check_decay_series(pdamp, source, work):
    """pdamp decay --method dem --snapshots 4: each bed's particles and container over the
    decay; the box follows the site (it moves along the drive, y here) and holds its spheres."""
    out = os.path.join(work, "decay")
    case = os.path.join(source, "tests", "cli", "data", "one_mode_dem_decay.json")
    subprocess.run([pdamp, "decay", case, "--method", "dem", "--snapshots", "4", "-o", out, "--overwrite", "--json"],
                   check=True, stdout=subprocess.DEVNULL)
    with open(case) as f:
        document = json.load(f)
    layer = document["dampers"][0]["layers"][0]
    size, radius, count = layer["container"]["inner_size_m"], layer["particles"]["radius_m"], layer["particles"]["count"]
    name = "damper_1"
    particles = ElementTree.parse(os.path.join(out, "particles_%s.pvd" % name)).getroot().find("Collection").findall("DataSet")
    containers = ElementTree.parse(os.path.join(out, "container_%s.pvd" % name)).getroot().find("Collection").findall("DataSet")
    assert len(particles) == len(containers) == 4, (len(particles), len(containers))
    times = [float(d.get("timestep")) for d in particles]
    assert times == sorted(times) and times == [float(d.get("timestep")) for d in containers], times
    centres_along = []
    for p, c in zip(particles, containers):
        spheres = read_polydata(os.path.join(out, p.get("file")))
        box = read_polydata(os.path.join(out, c.get("file")))
        assert spheres.GetNumberOfPoints() == count
        bounds = box.GetBounds()
        for axis in range(3):
            assert abs((bounds[2 * axis + 1] - bounds[2 * axis]) - size[axis]) < 1e-12, (axis, bounds)
        centres = vtk_to_numpy(spheres.GetPoints().GetData())
        for axis in range(3):
            assert (centres[:, axis] >= bounds[2 * axis] + 0.9 * radius).all(), (p.get("file"), axis)
            assert (centres[:, axis] <= bounds[2 * axis + 1] - 0.9 * radius).all(), (p.get("file"), axis)
        centres_along.append(0.5 * (bounds[0] + bounds[1]))
    assert len(set(centres_along)) > 1, centres_along  # the container moves with the decaying structure
    return len(particles)


if __name__ == "__main__":
    main()
