// Options of the optimiser module.
#include "pdamp/optimizer/options.hpp"
