/* Odin's per-step C code, compiled into the _odin_ode extension. */
#ifndef ODIN_STEP_H
#define ODIN_STEP_H
#include <ode/ode.h>
#endif
