// bed_packing: implementation pending (helper in progress).
#include "pdamp/formulas/bed_packing.hpp"
