/* Odin's per-step hot work in C (see odin_step.h). */
#include "odin_step.h"
