// Writes the seed of the checkpoint fuzz target (tests/fuzz/corpus/checkpoint/): a free decay
// of fuzz::checkpoint_model() with fuzz::checkpoint_dampers(), 0.02 s into its run, as pdamp
// decay --method dem leaves it. Usage: make_checkpoint_seed FILE (rerun when the layout of a
// state changes; the regression test feeds the seed and requires it accepted).
#include <cstdio>
#include <fstream>

#include "fuzz_readers.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_checkpoint_seed FILE\n");
    return 2;
  }
  namespace st = pdamp::structure;
  namespace dem = pdamp::dem_reference;
  st::DecayRun options;
  options.initial_modal_displacements = Eigen::VectorXd::Constant(1, 0.01);
  options.duration_s = 0.02;
  options.sample_interval_s = 0.002;
  st::CosimulationState state;
  const st::CosimulationResult result =
      st::cosimulate(pdamp::fuzz::checkpoint_model(), pdamp::fuzz::checkpoint_dampers(), options, state);
  dem::StateWriter out;
  st::save_cosimulation_state(state, out);
  st::save_cosimulation_result(result, out);
  dem::CheckpointHeader header;
  header.kind = "decay_dem";
  header.case_hash = "fuzz seed";
  header.physics_model_version = dem::kPhysicsModelVersion;
  header.settings = "duration_s 0.1";
  header.simulated_time_s = result.simulated_time_s;
  header.end_time_s = 0.1;
  std::ofstream(argv[1], std::ios::binary) << dem::encode_checkpoint(header, out.bytes());
  return 0;
}
