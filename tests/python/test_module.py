"""The Python module pdamp (python/pdamp_module.cpp) against the command line's numbers.

Run by ctest (label python) with PYTHONPATH at the built module, PDAMP_BINARY the pdamp
program and PDAMP_SOURCE_DIR the repository.
"""
import json
import os
import signal
import subprocess
import threading

import numpy as np
import pytest

import pdamp

BINARY = os.environ["PDAMP_BINARY"]
SOURCE = os.environ["PDAMP_SOURCE_DIR"]


def case_file(name):
    return os.path.join(SOURCE, "cases", name)


def cli_json(*args):
    """pdamp's --json output of one command (an argument vector: no shell)."""
    done = subprocess.run([BINARY, *args, "--json"], check=True, capture_output=True, text=True)
    return json.loads(done.stdout)


def small_dem_case():
    """The shipped 36-sphere layer with soft contacts and one analysed period."""
    with open(case_file("low_intensity_36_spheres.json")) as f:
        document = json.load(f)
    document["dem"] = {"stiffness_softening": 1e-3, "transient_periods": 0, "analysed_periods": 1}
    return document


def test_closed_forms_equal_pdamp_loss_and_broadcast():
    # The same point through the command line and the module: the same double, printed by
    # the JSON writer to 17 digits (so equal to the bit).
    for model, h, x, f in (("rolling", 0.1, 0.04, 2.0), ("bouncing", 0.01, 0.0032, 50.0), ("auto", 0.1, 0.02, 2.0)):
        expected = cli_json("loss", "--model", model, "--clearance", str(h), "--amplitude", str(x), "--frequency", str(f))
        assert pdamp.reduced_loss_factor(model, h, x, f) == expected["eta_star"]
        assert pdamp.loss(model, h, x, f)["eta_star"] == expected["eta_star"]
    # Vectorised: an η* curve over strokes, each point the scalar call's.
    strokes = np.linspace(0.005, 0.08, 40)
    curve = pdamp.reduced_loss_factor("rolling", 0.1, strokes, 2.0)
    assert curve.shape == strokes.shape
    assert all(curve[i] == pdamp.reduced_loss_factor("rolling", 0.1, float(x), 2.0) for i, x in enumerate(strokes))
    # The rolling optimum near 0.4 h (docs/theory.md §3): the curve's largest value is there.
    assert 0.035 <= strokes[np.argmax(curve)] <= 0.05


def test_bad_values_raise_value_errors():
    with pytest.raises(ValueError):
        pdamp.reduced_loss_factor("rolling", -0.1, 0.04, 2.0)
    with pytest.raises(ValueError, match="must be rolling, bouncing, auto or scattered"):
        pdamp.reduced_loss_factor("rollin", 0.1, 0.04, 2.0)


def test_a_bad_case_raises_input_error_with_file_pointer_and_rule(tmp_path):
    document = small_dem_case()
    document["damper"]["particles"]["radius_m"] = -0.005
    with pytest.raises(pdamp.InputError) as raised:
        pdamp.load_case(document, str(tmp_path / "bad.json"))
    error = raised.value
    assert isinstance(error, ValueError)
    assert error.file.endswith("bad.json")
    assert error.pointer == "/damper/particles/radius_m"
    assert "must be" in error.rule
    # The same from a file, as pdamp validate says it.
    path = tmp_path / "bad_file.json"
    path.write_text(json.dumps(document))
    with pytest.raises(pdamp.InputError) as raised:
        pdamp.load_case(str(path))
    assert raised.value.pointer == "/damper/particles/radius_m"


def test_a_small_dem_run_equals_pdamp_dem(tmp_path):
    document = small_dem_case()
    path = tmp_path / "small.json"
    path.write_text(json.dumps(document))
    reports = []
    result = pdamp.dem(pdamp.load_case(str(path)), progress=reports.append)
    expected = cli_json("dem", str(path))
    # The DEM is deterministic: the module's run is the command's to the bit.
    assert result["eta_star"] == expected["eta_star"]
    assert result["apparent_mass_kg"] == expected["apparent_mass_kg"]
    assert result["energy_balance_error"] < 0.02
    series = result["series"]
    assert isinstance(series["time_s"], np.ndarray)
    assert series["time_s"].shape == series["force_n"].shape
    assert reports and reports[-1]["label"] == "pdamp dem"


def test_structure_studies_return_dicts_of_arrays():
    link = pdamp.load_case(case_file("manipulator_link_decay.json"))
    decay = pdamp.decay(link)
    expected = cli_json("decay", case_file("manipulator_link_decay.json"))
    assert decay["settling_time_s"] == expected["settling_time_s"]
    bare = decay["without_particles"]
    assert bare["envelope_m"][-1] > decay["decay"]["final_envelope_m"]
    beam = pdamp.load_case(case_file("beam_base_excited.json"))
    frf = pdamp.frf(beam)
    curves = frf["curves"]
    assert curves["frequency_hz"].shape == curves["magnitude"].shape == curves["magnitude_without_particles"].shape
    # Without particles the resonance peak is far higher (the damper's purpose).
    assert np.nanmax(curves["magnitude_without_particles"]) > 10 * np.nanmax(curves["magnitude"])
    modes = pdamp.modes(beam)
    assert modes["modes"][0]["frequency_hz"] > 0


def test_optimize_sizes_a_clearance_as_pdamp_optimize():
    beam = pdamp.load_case(case_file("beam_clearance.json"))
    sized = pdamp.optimize(beam, verify=False)
    expected = cli_json("optimize", case_file("beam_clearance.json"), "--no-verify")
    assert sized["task"] == "clearance"
    assert sized["design"]["clearance_m"] == expected["design"]["clearance_m"]
    assert sized["verification"] is None


def interrupted_after_a_second(tmp_path, document, run):
    """Runs run(case, progress) on the case `document`, sends SIGINT after a second and
    expects KeyboardInterrupt; returns the progress reports seen."""
    path = tmp_path / "case.json"
    path.write_text(json.dumps(document))
    case = pdamp.load_case(str(path))
    reports = []
    timer = threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            run(case, reports.append)
    finally:
        timer.cancel()
    return reports


def test_keyboard_interrupt_stops_a_dem_run(tmp_path):
    document = small_dem_case()
    document["dem"]["analysed_periods"] = 2000  # minutes: only the interrupt ends it soon
    reports = interrupted_after_a_second(tmp_path, document, lambda case, progress: pdamp.dem(case, progress=progress))
    # Stopped where it was, not at its end: the last report is early in the 2000 periods.
    assert reports and reports[-1]["done"] < 0.5 * reports[-1]["total"]


def test_keyboard_interrupt_stops_a_dem_field_before_its_next_point(tmp_path):
    document = small_dem_case()
    document["dem"]["analysed_periods"] = 20  # about a second a point: the interrupt lands mid-sweep
    document["field"] = {"axis0": {"min": 1.5, "max": 2.5, "count": 4}, "axis1": {"min": 0.015, "max": 0.07, "count": 4},
                         "threads": 1}
    reports = interrupted_after_a_second(tmp_path, document,
                                         lambda case, progress: pdamp.field(case, source="dem", progress=progress))
    # The point in flight finished, no other started: the sweep ended well before its 16 points.
    assert reports and all(r["counts_points"] for r in reports)
    assert reports[-1]["done"] < reports[-1]["total"] == 16
