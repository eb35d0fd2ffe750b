// collect_and_collide: implementation pending (helper in progress).
#include "pdamp/formulas/collect_and_collide.hpp"
