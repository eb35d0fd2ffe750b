// The Python module `pdamp` (docs/python.md): the closed forms vectorised over numpy arrays,
// case loading from a file or a dict, and the studies of the tasks library (dem, field,
// modes, frf, decay, optimize) returning their result JSON as dicts, numeric lists as numpy
// arrays. Progress goes to a Python callback, Ctrl-C (KeyboardInterrupt) stops a run at its
// next stop poll, and errors are Python exceptions carrying file, pointer and rule.
// Like the command line, this only converts, calls and returns: the work is the libraries'.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <initializer_list>
#include <optional>
#include <string>

#include "pdamp/case_file/case.hpp"
#include "pdamp/case_file/ranges.hpp"
#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/base/input_error.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/run_errors.hpp"
#include "pdamp/surrogate/effective_field.hpp"
#include "pdamp/tasks/closed_forms.hpp"
#include "pdamp/tasks/decay.hpp"
#include "pdamp/tasks/dem_run.hpp"
#include "pdamp/base/executor.hpp"
#include "pdamp/tasks/field.hpp"
#include "pdamp/tasks/filling_ratios.hpp"
#include "pdamp/tasks/frf.hpp"
#include "pdamp/tasks/modes.hpp"
#include "pdamp/tasks/clearance.hpp"
#include "pdamp/tasks/placement.hpp"
#include "pdamp/base/run_hooks.hpp"

namespace py = pybind11;
using nlohmann::json;
using namespace pdamp;

namespace {

/// JSON as Python: objects as dicts, arrays of numbers as 1-D float64 numpy arrays, arrays of
/// equal-length number arrays as 2-D ones, other arrays as lists.
py::object to_python(const json& v) {
  switch (v.type()) {
    case json::value_t::null: return py::none();
    case json::value_t::boolean: return py::bool_(v.get<bool>());
    case json::value_t::number_integer: return py::int_(v.get<long long>());
    case json::value_t::number_unsigned: return py::int_(v.get<unsigned long long>());
    case json::value_t::number_float: return py::float_(v.get<double>());
    case json::value_t::string: return py::str(v.get<std::string>());
    case json::value_t::object: {
      py::dict out;
      for (const auto& [key, value] : v.items()) out[py::str(key)] = to_python(value);
      return out;
    }
    case json::value_t::array: {
      const bool numbers = !v.empty() && std::all_of(v.begin(), v.end(), [](const json& x) { return x.is_number() || x.is_null(); });
      if (numbers) {
        py::array_t<double> out(static_cast<py::ssize_t>(v.size()));
        auto data = out.mutable_unchecked<1>();
        for (std::size_t i = 0; i < v.size(); ++i) data(static_cast<py::ssize_t>(i)) = v[i].is_null() ? NAN : v[i].get<double>();
        return out;
      }
      py::list out;
      for (const auto& x : v) out.append(to_python(x));
      return out;
    }
    default: return py::none();
  }
}

/// A Python dict (or list, number, ...) as JSON, through the json module: what json.dumps
/// accepts is a case document. What it refuses (a set, bytes keys, NaN, nesting beyond
/// Python's recursion limit) is a ValueError naming the cause; the text is then parsed as a
/// case file is (base::parse_json_document: no nesting deeper than a case needs).
json from_python(const py::handle& object) {
  std::string text;
  // numpy arrays and scalars (what Case.resolved and the studies return) as lists and numbers.
  const py::cpp_function plain([](const py::object& o) -> py::object {
    if (py::hasattr(o, "tolist")) return o.attr("tolist")();
    throw py::type_error("Object of type " + py::str(o.get_type().attr("__name__")).cast<std::string>() +
                         " is not JSON serializable");
  });
  try {
    text = py::module_::import("json").attr("dumps")(object, py::arg("allow_nan") = false, py::arg("default") = plain)
               .cast<std::string>();
  } catch (py::error_already_set& e) {
    if (!e.matches(PyExc_TypeError) && !e.matches(PyExc_ValueError) && !e.matches(PyExc_RecursionError)) throw;
    throw py::value_error("the case dict is not a JSON document: " + py::str(e.type().attr("__name__")).cast<std::string>() +
                          ": " + py::str(e.value()).cast<std::string>());
  }
  return base::parse_json_document(text, "<dict>");
}

/// `value` if it lies in `range` (the command line's flag ranges, pdamp/case_file/ranges.hpp:
/// one source of truth), else ValueError "name = value: must be ...".
double in_range(const char* name, double value, const case_file::Range& range) {
  if (!range.contains(value)) throw py::value_error(std::string(name) + " = " + base::format_number(value, 10) + ": " + range.text());
  return value;
}

/// `value` if it is one of `allowed`, else ValueError naming the argument and the choices (a
/// misspelt method once ran another one silently).
const std::string& choice(const std::string& argument, const std::string& value, std::initializer_list<const char*> allowed) {
  std::string list;
  for (const char* a : allowed) {
    if (value == a) return value;
    list += (list.empty() ? "" : ", ") + std::string(a);
  }
  throw py::value_error(argument + " = '" + value + "': must be one of " + list);
}

/// The hooks of a run started from Python: progress to the callback (with the GIL), a
/// pending KeyboardInterrupt (Python's SIGINT handler, run by PyErr_CheckSignals) as a stop
/// request, whose exception is restored when the run has ended.
class PythonHooks : public base::RunHooks {
 public:
  explicit PythonHooks(py::object progress) : progress_(std::move(progress)) {}
  void progress(const base::Progress& p) override {
    if (progress_.is_none()) return;
    py::gil_scoped_acquire gil;
    try {
      progress_(py::dict(py::arg("label") = p.label, py::arg("stage") = p.stage, py::arg("done") = p.done,
                         py::arg("total") = p.total, py::arg("counts_points") = p.counts_points,
                         py::arg("steps_per_s") = p.steps_per_s, py::arg("eta_s") = p.eta_s));
    } catch (py::error_already_set& e) {
      keep(e);
    }
  }
  /// Polled every few steps: Python's signal handlers run at most every 20 ms (taking the
  /// GIL each time would cost the DEM a few per cent), so Ctrl-C stops a run within that.
  int stop_requested() override {
    const auto now = std::chrono::steady_clock::now().time_since_epoch().count();
    if (now - last_check_.load(std::memory_order_relaxed) < kCheckInterval.count()) return stopping_.load();
    last_check_.store(now, std::memory_order_relaxed);
    py::gil_scoped_acquire gil;
    if (!pending_ && PyErr_CheckSignals() != 0) pending_ = py::error_already_set();
    stopping_.store(pending_ ? SIGINT : 0);
    return stopping_.load();
  }
  /// After the run: the callback's exception or the KeyboardInterrupt, if any.
  void rethrow() {
    if (pending_) {
      auto e = std::move(*pending_);
      pending_.reset();
      throw e;
    }
  }

 private:
  void keep(py::error_already_set& e) {
    if (!pending_) pending_ = std::move(e);
  }
  static constexpr std::chrono::steady_clock::duration kCheckInterval = std::chrono::milliseconds(20);
  py::object progress_;
  std::optional<py::error_already_set> pending_;  // touched with the GIL held only
  std::atomic<std::chrono::steady_clock::rep> last_check_{0};
  std::atomic<int> stopping_{0};
};

/// Runs `study` without the GIL (its threads call the hooks, which take it), then raises
/// what Python asked for on the way (a KeyboardInterrupt, the callback's exception).
template <class Study>
auto run_study(PythonHooks& hooks, Study&& study) {
  try {
    auto result = [&] {
      py::gil_scoped_release released;
      return study();
    }();
    hooks.rethrow();
    return result;
  } catch (const base::Interrupted&) {
    hooks.rethrow();
    throw;
  }
}

case_file::Case load_case(const py::object& source, const std::string& path) {
  if (py::isinstance<py::dict>(source)) return case_file::load_case_document(from_python(source), path.empty() ? "<dict>" : path);
  // A path: str or os.PathLike, nothing else (42 once read as the file "42").
  if (!py::isinstance<py::str>(source) && !py::hasattr(source, "__fspath__"))
    throw py::type_error("load_case: source must be a path (str or os.PathLike) or a dict, got " +
                         py::str(source.get_type().attr("__name__")).cast<std::string>());
  return case_file::load_case(py::str(py::module_::import("os").attr("fspath")(source)).cast<std::string>());
}

formulas::DamperModel model_of(const std::string& name) {
  const auto model = formulas::damper_model_from_string(name);
  if (!model) throw py::value_error("model '" + name + "': must be rolling, bouncing, auto or scattered");
  return *model;
}

formulas::ModelOptions model_options(double rolling_inertia_factor, double base_friction, double bed_restitution) {
  formulas::ModelOptions o;
  o.rolling_inertia_factor = rolling_inertia_factor;
  o.base_friction = base_friction;
  o.bed_restitution = bed_restitution;
  return o;
}

}  // namespace

PYBIND11_MODULE(pdamp, m) {
  m.doc() = "pdamp: design and optimisation of particle dampers (docs/python.md). SI units throughout.";

  // Errors: InputError (a ValueError) names the file, the JSON pointer and the rule broken;
  // NumericalError (a RuntimeError) a run that failed on valid input.
  static py::exception<base::InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<base::NumericalError> numerical_error(m, "NumericalError", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const base::InputError& e) {
      py::object error = py::reinterpret_borrow<py::object>(input_error.ptr())(e.what());
      error.attr("file") = e.file();
      error.attr("pointer") = e.pointer();
      error.attr("rule") = e.rule();
      PyErr_SetObject(input_error.ptr(), error.ptr());
    } catch (const base::NumericalError& e) {
      numerical_error(e.what());
    } catch (const base::Interrupted& e) {
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    }
  });

  m.attr("__version__") = PDAMP_VERSION;

  // ---- The closed forms (Level II), vectorised: numpy broadcasting over the three numbers.
  m.def(
      "reduced_loss_factor",
      [](const std::string& model, py::object clearance_m, py::object stroke_m, py::object frequency_hz,
         double rolling_inertia_factor, double base_friction, double bed_restitution) {
        const auto kind = model_of(model);
        const auto options = model_options(rolling_inertia_factor, base_friction, bed_restitution);
        if (const auto problems = options.validate(); !problems.empty()) throw py::value_error(problems.front());
        auto eta = [&](double h, double x, double f) {
          return formulas::reduced_loss_factor_counted(kind, in_range("clearance_m", h, case_file::limits::kClearance),
                                                       in_range("stroke_m", x, case_file::limits::kStroke),
                                                       in_range("frequency_hz", f, case_file::limits::kFrequency), options)
              .eta_star;
        };
        try {
          return py::vectorize(eta)(clearance_m, stroke_m, frequency_hz);
        } catch (const py::error_already_set&) {
          throw;
        } catch (const std::runtime_error& e) {
          // pybind11's broadcasting failure ("incompatible size/dimension of inputs") is the
          // caller's arrays: a ValueError, as numpy says it.
          throw py::value_error(std::string("clearance_m, stroke_m and frequency_hz do not broadcast: ") + e.what());
        }
      },
      py::arg("model"), py::arg("clearance_m"), py::arg("stroke_m"), py::arg("frequency_hz"),
      py::arg("rolling_inertia_factor") = 0.4, py::arg("base_friction") = 0.3, py::arg("bed_restitution") = 0.0,
      "η* of the closed-form model ('rolling', 'bouncing', 'auto', 'scattered') at clearance h, stroke X and\n"
      "frequency f (m, m, Hz; numbers or numpy arrays, broadcast). As `pdamp loss`; ValueError for\n"
      "a value out of range.");
  m.def(
      "loss",
      [](const std::string& model, double clearance_m, double stroke_m, double frequency_hz, std::optional<double> bed_mass_kg,
         bool curve) {
        tasks::LossOptions o;
        o.model = model_of(model);
        o.clearance_m = in_range("clearance_m", clearance_m, case_file::limits::kClearance);
        o.amplitude_m = in_range("stroke_m", stroke_m, case_file::limits::kStroke);
        o.frequency_hz = in_range("frequency_hz", frequency_hz, case_file::limits::kFrequency);
        o.bed_mass_kg = bed_mass_kg;
        o.with_curve = curve;
        const auto study = tasks::run_loss(o);
        json out = tasks::to_json(study);
        out["warnings"] = study.warnings;
        return to_python(out);
      },
      py::arg("model"), py::arg("clearance_m"), py::arg("stroke_m"), py::arg("frequency_hz"), py::arg("bed_mass_kg") = py::none(),
      py::arg("curve") = false, "`pdamp loss` as a dict: η*, E_diss, the landmarks, warnings (the same keys as --json).");

  // ---- Cases.
  py::class_<case_file::Case>(m, "Case", "A checked case (docs/cases.md); load_case() makes one.")
      .def_property_readonly("name", [](const case_file::Case& c) { return c.name; })
      .def_property_readonly("path", [](const case_file::Case& c) { return c.path; })
      .def_property_readonly("resolved", [](const case_file::Case& c) { return to_python(c.resolved); },
                             "the case with every default resolved (case_resolved.json)")
      .def("__repr__", [](const case_file::Case& c) { return "<pdamp.Case '" + c.name + "' from " + c.path + ">"; });
  m.def("load_case", &load_case, py::arg("source"), py::arg("path") = "",
        "A case from a file path, or from a dict (read as if it were the file `path`: relative paths\n"
        "in it resolve against that file's folder). InputError names the file, pointer and rule.");

  // ---- The studies. Each takes `progress`, a callable given a dict per report (label, stage,
  // done, total, counts_points, steps_per_s, eta_s), or None.
  m.def(
      "dem",
      [](const case_file::Case& c, std::optional<double> amplitude_m, std::optional<double> frequency_hz,
         std::optional<int> periods, std::optional<int> threads, py::object progress) {
        tasks::DemRunOptions o;
        o.amplitude_m = amplitude_m;
        o.frequency_hz = frequency_hz;
        o.analysed_periods = periods;
        o.threads = threads;
        const auto plan = tasks::plan_dem(c, o);
        PythonHooks hooks(progress);
        const auto r = run_study(hooks, [&] { return tasks::run_dem(c, plan, {}, hooks); });
        json out = tasks::to_json(r);
        const auto& s = r.dem.series;
        out["series"] = {{"time_s", s.time_s},
                         {"container_position_m", s.container_position_m},
                         {"container_velocity_m_s", s.container_velocity_m_s},
                         {"force_n", s.force_n},
                         {"bed_relative_position_m", s.bed_relative_position_m},
                         {"kinetic_energy_j", s.kinetic_energy_j}};
        out["warnings"] = r.warnings;
        return to_python(out);
      },
      py::arg("case"), py::arg("amplitude_m") = py::none(), py::arg("frequency_hz") = py::none(),
      py::arg("periods") = py::none(), py::arg("threads") = py::none(), py::arg("progress") = py::none(),
      "`pdamp dem`: the reference DEM of the case's damper under x = X sin(2πft); the result dict\n"
      "with the time series ('series') as numpy arrays.");
  m.def(
      "field",
      [](const case_file::Case& c, const std::string& source, py::object progress) {
        tasks::FieldOptions o;
        o.source = choice("source", source, {"formulas", "dem"});
        auto& executor = base::local_executor();
        const auto plan = tasks::plan_field(c, o, executor);
        PythonHooks hooks(progress);
        const auto r = run_study(hooks, [&] { return tasks::run_field(c, plan, hooks, executor); });
        json out = surrogate::to_json(r.field);
        out["warnings"] = r.warnings;
        return to_python(out);
      },
      py::arg("case"), py::arg("source") = "formulas", py::arg("progress") = py::none(),
      "`pdamp field`: the effective field over the case's grid (source 'formulas' or 'dem'), as field.json.");
  m.def(
      "modes",
      [](const case_file::Case& c, const std::optional<std::string>& method, py::object progress) {
        PythonHooks hooks(progress);
        tasks::ModesOptions o;
        if (method) {
          const std::string name = choice("method", *method, {"formulas", "field", "calibrated"});
          o.calibrated = name == "calibrated";
          if (name == "field") o.method = case_file::LossMethod::kField;
        }
        json out = tasks::to_json(run_study(hooks, [&] { return tasks::run_modes(c, o, hooks); }), tasks::OutputFolder{});
        return to_python(out);
      },
      py::arg("case"), py::arg("method") = py::none(), py::arg("progress") = py::none(),
      "`pdamp modes`: natural frequencies, shapes and backbones (and the task's calibration, dem_check and clearance_search); "
      "method None: calibrated when the task has a calibration, else formulas.");
  m.def(
      "frf",
      [](const case_file::Case& c, const std::string& method, py::object progress) {
        tasks::FrfOptions o;
        if (choice("method", method, {"formulas", "field", "dem"}) == "dem") {
          o.method = tasks::FrfMethod::kDem;
          o.dem = tasks::default_dem_frf_options(c);
        } else {
          o.method = method == "field" ? tasks::FrfMethod::kField : tasks::FrfMethod::kFormulas;
        }
        PythonHooks hooks(progress);
        const auto r = run_study(hooks, [&] { return tasks::run_frf(c, o, hooks, base::local_executor()); });
        json out = tasks::to_json(r, tasks::OutputFolder{});
        if (r.harmonic) {
          // The curves: per frequency, the structure without particles and the largest stable
          // root with them (NaN where no root is stable), first output.
          json f = json::array(), bare = json::array(), with = json::array(), held = json::array();
          for (const auto& p : r.harmonic->response.points) {
            f.push_back(p.frequency_hz);
            bare.push_back(p.linear_outputs.empty() ? NAN : std::abs(p.linear_outputs.front()));
            double largest = NAN;
            for (const auto& root : p.roots)
              if (root.stability == structure::Stability::kStable && !root.outputs.empty())
                largest = std::isnan(largest) ? std::abs(root.outputs.front()) : std::max(largest, std::abs(root.outputs.front()));
            // Where no root is stable the bed is held at its onset (pdamp frf's held states).
            const bool at_jump = std::isnan(largest) && !p.held_at_jump.empty() && !p.held_at_jump.front().outputs.empty();
            if (at_jump) largest = std::abs(p.held_at_jump.front().outputs.front());
            with.push_back(largest);
            held.push_back(at_jump ? 1.0 : 0.0);
          }
          out["curves"] = {{"frequency_hz", f}, {"magnitude_without_particles", bare}, {"magnitude", with}, {"held_at_jump", held}};
        }
        out["warnings"] = r.warnings;
        return to_python(out);
      },
      py::arg("case"), py::arg("method") = "formulas", py::arg("progress") = py::none(),
      "`pdamp frf` (method 'formulas', 'field' or 'dem'): peaks, branches, and for the harmonic balance\n"
      "'curves' (frequency_hz, magnitude, magnitude_without_particles, held_at_jump) as numpy arrays.");
  m.def(
      "decay",
      [](const case_file::Case& c, const std::string& method, py::object progress) {
        tasks::DecayOptions o;
        o.method = choice("method", method, {"formulas", "field", "dem"}) == "dem" ? tasks::DecayMethod::kDem
                   : method == "field" ? tasks::DecayMethod::kField
                                       : tasks::DecayMethod::kFormulas;
        PythonHooks hooks(progress);
        const auto r = run_study(hooks, [&] { return tasks::run_decay(c, o, hooks); });
        json out = tasks::to_json(r, tasks::OutputFolder{});
        json t = json::array(), bare = json::array();
        for (const auto& s : r.without_beds.samples) t.push_back(s.time_s), bare.push_back(s.threshold_measure_m);
        out["without_particles"] = {{"time_s", t}, {"envelope_m", bare}};
        out["warnings"] = r.warnings;
        return to_python(out);
      },
      py::arg("case"), py::arg("method") = "formulas", py::arg("progress") = py::none(),
      "`pdamp decay` (method 'formulas', 'field' or 'dem'): settling time, damping ratio, and the same\n"
      "release without particles ('without_particles': time_s, envelope_m).");
  m.def(
      "optimize",
      [](const case_file::Case& c, bool verify, py::object progress) {
        PythonHooks hooks(progress);
        if (c.task.kind == case_file::TaskKind::kPlacement) {
          tasks::PlacementOptions o;
          o.skip_verify = !verify;
          return to_python(tasks::to_json(run_study(hooks, [&] { return tasks::run_placement(c, o, hooks); })));
        }
        if (c.task.kind == case_file::TaskKind::kClearance) {
          tasks::ClearanceOptions o;
          o.skip_verify = !verify;
          const auto r = run_study(hooks, [&] { return tasks::run_clearance(c, o, hooks); });
          json out = tasks::to_json(r);
          out["warnings"] = r.warnings;
          return to_python(out);
        }
        tasks::FillingRatiosOptions o;
        o.skip_verify = !verify;
        const auto r = run_study(hooks, [&] { return tasks::run_filling_ratios(c, o, hooks, base::local_executor()); });
        json out = tasks::to_json(r);
        out["warnings"] = r.warnings;
        return to_python(out);
      },
      py::arg("case"), py::arg("verify") = true, py::arg("progress") = py::none(),
      "`pdamp optimize` on a filling_ratios, placement or clearance case: the designs, the solver\n"
      "and, with verify, the DEM verification (the task's verify block).");
}
