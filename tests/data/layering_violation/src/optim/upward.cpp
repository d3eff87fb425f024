// A fixture of the layering test (tests/CMakeLists.txt, test layers_refuse_an_upward_include):
// optim/ may use core/ alone, so this include must be refused.
#include "mcrewave/mcre/objective.h"
