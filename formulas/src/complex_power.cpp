// complex_power: implementation pending (helper in progress).
#include "pdamp/formulas/complex_power.hpp"
