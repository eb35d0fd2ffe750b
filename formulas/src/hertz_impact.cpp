// hertz_impact: implementation pending (helper in progress).
#include "pdamp/formulas/hertz_impact.hpp"
