// pdamp's version and build (version.hpp); the only source that sees the configured
// PDAMP_VERSION, PDAMP_GIT_COMMIT, PDAMP_BUILD_TYPE and PDAMP_COMPILER (cli/CMakeLists.txt),
// so that a new commit recompiles one small file.
#include "version.hpp"

#include <sstream>

#include "distributed.hpp"
#include "pdamp/dem_reference/world.hpp"

namespace pdamp::cli {

std::string version() { return PDAMP_VERSION; }

std::string version_text() {
  std::ostringstream out;
  out << "pdamp " << PDAMP_VERSION << "\n"
      << "commit " << PDAMP_GIT_COMMIT << " (the one the build was configured from)\n"
      << "DEM physics model version " << dem_reference::kPhysicsModelVersion << "\n"
      << "build " << (std::string(PDAMP_BUILD_TYPE).empty() ? "default" : PDAMP_BUILD_TYPE) << ", " << PDAMP_COMPILER
      << ", MPI " << (distributed::built_with_mpi() ? "on" : "off") << "\n";
  return out.str();
}

std::string provenance_line() {
  std::ostringstream out;
  out << "pdamp " << PDAMP_VERSION << ", commit " << PDAMP_GIT_COMMIT << ", DEM physics model "
      << dem_reference::kPhysicsModelVersion;
  return out.str();
}

}  // namespace pdamp::cli
