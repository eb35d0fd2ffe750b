// cor_models: implementation pending (helper in progress).
#include "pdamp/formulas/cor_models.hpp"
