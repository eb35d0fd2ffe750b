// What this pdamp is: version, the commit the build was configured from, the DEM physics
// model version and the build's options (pdamp --version, and a report's provenance).
#pragma once

#include <string>

namespace pdamp::cli {

/// "0.1.0"
std::string version();
/// The lines of pdamp --version.
std::string version_text();
/// One line for a result's provenance: "pdamp 0.1.0, commit 1a2b3c4d5e6f, DEM physics model 3".
std::string provenance_line();

}  // namespace pdamp::cli
