/* The part of ODE's C API (libode 0.16, double precision) and of odin_step.h that Python sees. */
typedef double dReal;
int dInitODE2(unsigned int uiInitFlags);
void dCloseODE(void);
int dCheckConfiguration(const char *token);
