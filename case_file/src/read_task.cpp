// Format 2 `task`: what `pdamp run` does, with the settings of its kind.
#include <algorithm>

#include "readers.hpp"

namespace pdamp::case_file::detail {

namespace {

FrfTask read_frf(ObjectReader& r, const Case& c) {
  FrfTask t;
  t.min_frequency_hz = r.number("min_frequency_hz", std::nullopt, limits::kFrequency, " Hz");
  t.max_frequency_hz = r.number("max_frequency_hz", std::nullopt, limits::kFrequency, " Hz");
  if (!(t.max_frequency_hz > t.min_frequency_hz)) r.fail("max_frequency_hz", "must be > min_frequency_hz");
  t.points = r.integer("points", FrfTask{}.points, 2, 100000);
  t.spacing = r.text("spacing", std::string("linear"), {"linear", "log"}) == "log" ? surrogate::AxisSpacing::kLog
                                                                                  : surrogate::AxisSpacing::kLinear;
  r.object("excitation", true, [&](ObjectReader& e) {
    const std::string kind = e.text("kind", std::nullopt, {"base", "force"});
    if (kind == "base") {
      t.excitation = FrfTask::Excitation::kBase;
      t.base_amplitude_m = e.number("amplitude_m", std::nullopt, limits::kStroke, " m");
    } else {
      t.excitation = FrfTask::Excitation::kForce;
      t.force_point = read_point_name(e, "point", c);
      t.force_amplitude_n = e.number("amplitude_n", std::nullopt, {0.0, limits::kForce.max, true}, " N");
    }
    t.direction = read_plane_direction(e, "direction", PlaneVector{0.0, 1.0});
  });
  return t;
}

DecayTask read_decay(ObjectReader& r, const Case& c) {
  DecayTask t;
  r.object("initial_state", true, [&](ObjectReader& s) {
    const std::string kind = s.text("kind", std::nullopt, {"static_load", "modal_amplitudes"});
    if (kind == "static_load") {
      t.initial_state = DecayTask::InitialState::kStaticLoad;
      t.load_point = read_point_name(s, "point", c);
      const auto force = s.number_array("force_n", limits::kForce, " N", 2);
      if (force.size() != 2) s.fail("force_n", "has " + std::to_string(force.size()) + " entries: must be [x, y]");
      if (force[0] == 0.0 && force[1] == 0.0) s.fail("force_n", "must not be zero (nothing would move)");
      t.load_force_n = {force[0], force[1]};
    } else {
      t.initial_state = DecayTask::InitialState::kModalAmplitudes;
      t.modal_amplitudes = s.number_array("values", {-10.0, 10.0}, "", 1);
    }
  });
  t.duration_s = r.number("duration_s", std::nullopt, limits::kDuration, " s");
  t.settling_threshold = r.number("settling_threshold", DecayTask{}.settling_threshold, {0.0, 1.0, true});
  if (t.settling_threshold >= 1.0) r.fail("settling_threshold", "must be < 1 (a fraction of the initial amplitude)");
  return t;
}

ModesTask read_modes(ObjectReader& r, const Case& c) {
  ModesTask t;
  const int available = c.structure->kind == StructureSpec::Kind::kBeam
                            ? c.structure->mode_count
                            : static_cast<int>(c.structure->modal_data->mode_count());
  t.mode_count = r.integer("mode_count", available, 1, available);
  t.backbone_min_amplitude_m = r.number("backbone_min_amplitude_m", std::nullopt, limits::kStroke, " m");
  t.backbone_max_amplitude_m = r.number("backbone_max_amplitude_m", std::nullopt, limits::kStroke, " m");
  if (!(t.backbone_max_amplitude_m > t.backbone_min_amplitude_m))
    r.fail("backbone_max_amplitude_m", "must be > backbone_min_amplitude_m");
  t.backbone_points = r.integer("backbone_points", ModesTask{}.backbone_points, 2, 10000);
  return t;
}

void read_task_object(ObjectReader& r, const Case& c, TaskSpec& task) {
  const std::string kind = r.text("kind", std::string("damper_design"), {"damper_design", "frf", "decay", "modes"});
  if (kind == "frf") {
    task.kind = TaskKind::kFrf;
    task.frf = read_frf(r, c);
  } else if (kind == "decay") {
    task.kind = TaskKind::kDecay;
    task.decay = read_decay(r, c);
  } else if (kind == "modes") {
    task.kind = TaskKind::kModes;
    task.modes = read_modes(r, c);
  }
}

}  // namespace

TaskSpec read_task(ObjectReader& root, const Case& c) {
  TaskSpec task;
  root.object("task", false, [&](ObjectReader& r) { read_task_object(r, c, task); });
  if (!root.has("task")) {
    ObjectReader defaults(root.file(), empty_object(), "/task", root.resolved()["task"]);
    read_task_object(defaults, c, task);
  }
  return task;
}

}  // namespace pdamp::case_file::detail
