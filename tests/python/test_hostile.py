"""Hostile calls of the Python module (docs/bad_inputs.md, "Python"): wrong types, NaN and
huge arrays, dicts that are no JSON document, misspelt choices and a progress callback that
fails. Each must raise a Python exception naming the cause (ValueError, TypeError,
pdamp.InputError), never crash, hang or silently run something else.

Run with the module's other tests (scripts/ci_python.sh).
"""
import json
import os

import numpy as np
import pytest

import pdamp

SOURCE = os.environ["PDAMP_SOURCE_DIR"]


def case_file(name):
    return os.path.join(SOURCE, "cases", name)


@pytest.mark.parametrize("h, x, f, message", [
    (float("nan"), 0.04, 2.0, "clearance_m = nan"),
    (0.1, float("inf"), 2.0, "stroke_m = inf"),
    (0.1, -0.04, 2.0, "stroke_m = -0.04"),
    (0.1, 0.04, 1e308, "frequency_hz"),
    (0.1, np.array([0.04, np.nan]), 2.0, "stroke_m = nan"),
    (np.ones(3), np.ones(4), 2.0, "do not broadcast"),
])
def test_closed_forms_refuse_bad_numbers_with_value_errors(h, x, f, message):
    with pytest.raises(ValueError, match=message):
        pdamp.reduced_loss_factor("rolling", h, x, f)


def test_closed_forms_take_a_large_array_and_refuse_wrong_types():
    strokes = np.full(1_000_000, 0.04)
    eta = pdamp.reduced_loss_factor("rolling", 0.1, strokes, 2.0)
    assert eta.shape == strokes.shape
    assert np.all(eta == pdamp.reduced_loss_factor("rolling", 0.1, 0.04, 2.0))
    with pytest.raises((TypeError, ValueError)):
        pdamp.reduced_loss_factor("rolling", "a", 0.04, 2.0)
    with pytest.raises(TypeError):
        pdamp.reduced_loss_factor("rolling", 0.1, np.array([object()]), 2.0)
    with pytest.raises(ValueError, match="bed_mass_kg = -1"):
        pdamp.loss("rolling", 0.1, 0.04, 2.0, bed_mass_kg=-1.0)


@pytest.mark.parametrize("source", [42, None, [1, 2], 3.5])
def test_load_case_takes_a_path_or_a_dict_only(source):
    # Once 42 was read as the file "42".
    with pytest.raises(TypeError, match="must be a path"):
        pdamp.load_case(source)


def deep(levels):
    document = {}
    inner = document
    for _ in range(levels):
        inner["a"] = {}
        inner = inner["a"]
    return document


@pytest.mark.parametrize("document, error, message", [
    ({"name": {1, 2}}, ValueError, "not a JSON document: TypeError"),
    ({"name": object()}, ValueError, "not a JSON document: TypeError"),
    ({"name": "x", "format_version": float("nan")}, ValueError, "not a JSON document: ValueError"),
    ({b"name": "x"}, ValueError, "not a JSON document: TypeError"),
    (deep(5000), ValueError, "not a JSON document: RecursionError"),
    (deep(100), pdamp.InputError, "nest"),
    ({1: "x"}, pdamp.InputError, "/name: required"),
])
def test_load_case_refuses_dicts_that_are_no_case(document, error, message):
    with pytest.raises(error, match=message):
        pdamp.load_case(document)


def test_a_misspelt_choice_is_refused_not_replaced():
    # Once 'bogus' ran the closed forms instead.
    decay = pdamp.load_case(case_file("manipulator_link_decay.json"))
    for study in (pdamp.modes, pdamp.frf, pdamp.decay):
        with pytest.raises(ValueError, match="method = 'bogus': must be one of"):
            study(decay, method="bogus")
    # A calibration needs a modes task: the frf case has none.
    with pytest.raises(pdamp.InputError, match="a calibration needs task kind modes"):
        pdamp.modes(pdamp.load_case(case_file("beam_base_excited.json")), method="calibrated")
    layer = pdamp.load_case(case_file("low_intensity_36_spheres.json"))
    with pytest.raises(ValueError, match="source = 'bogus'"):
        pdamp.field(layer, source="bogus")


def test_dem_arguments_out_of_range_or_of_the_wrong_type():
    layer = pdamp.load_case(case_file("low_intensity_36_spheres.json"))
    with pytest.raises(pdamp.InputError, match="analysed_periods"):
        pdamp.dem(layer, periods=-1)
    with pytest.raises(pdamp.InputError, match="amplitude_m"):
        pdamp.dem(layer, amplitude_m=float("nan"), periods=1)
    with pytest.raises(TypeError):
        pdamp.dem(layer, amplitude_m="x", periods=1)


def test_a_failing_progress_callback_stops_the_run_with_its_exception():
    with open(case_file("low_intensity_36_spheres.json")) as f:
        document = json.load(f)
    document["dem"] = {"stiffness_softening": 1e-3, "transient_periods": 0, "analysed_periods": 2}
    # numpy values in a dict are numbers and lists (as the studies return them).
    document["damper"]["gravity_m_s2"] = np.array([0.0, 0.0, -9.80665])
    document["damper"]["particles"]["count"] = np.int64(36)
    layer = pdamp.load_case(document, case_file("low_intensity_36_spheres.json"))
    calls = []

    def failing(report):
        calls.append(report)
        raise ArithmeticError("the caller's own error")

    with pytest.raises(ArithmeticError, match="the caller's own error"):
        pdamp.dem(layer, periods=2, progress=failing)
    assert len(calls) >= 1
    with pytest.raises(TypeError):
        pdamp.dem(layer, periods=1, progress=5)
