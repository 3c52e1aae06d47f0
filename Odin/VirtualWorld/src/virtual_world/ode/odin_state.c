/* Bodies' dynamic state read and written bit for bit (see odin_step.h), for snapshots.
 *
 * ODE's own setter dBodySetQuaternion renormalises the quaternion it is given, and one
 * normalisation of an already unit quaternion changes its last bits for about a quarter of the
 * bodies of a pile (measured): a state put back through it would not continue as it did. So the
 * quaternion and rotation matrix are written where dBodyGetQuaternion and dBodyGetRotation
 * point (ODE's body record itself), then dBodySetPosition marks the body's geoms as moved. */
#include "odin_step.h"

#include <math.h>
#include <string.h>

void odin_read_body_states(dBodyID *bodies, int n, double *out) {
    for (int i = 0; i < n; ++i) {
        double *s = out + (size_t)i * ODIN_BODY_STATE_SIZE;
        memcpy(s, dBodyGetPosition(bodies[i]), 3 * sizeof(double));
        memcpy(s + 3, dBodyGetQuaternion(bodies[i]), 4 * sizeof(double));
        memcpy(s + 7, dBodyGetRotation(bodies[i]), 12 * sizeof(double));
        memcpy(s + 19, dBodyGetLinearVel(bodies[i]), 3 * sizeof(double));
        memcpy(s + 22, dBodyGetAngularVel(bodies[i]), 3 * sizeof(double));
        s[25] = dBodyIsEnabled(bodies[i]) ? 1.0 : 0.0;
    }
}

void odin_write_body_states(dBodyID *bodies, int n, const double *in) {
    for (int i = 0; i < n; ++i) {
        const double *s = in + (size_t)i * ODIN_BODY_STATE_SIZE;
        dBodyID b = bodies[i];
        memcpy((dReal *)dBodyGetQuaternion(b), s + 3, 4 * sizeof(double));
        memcpy((dReal *)dBodyGetRotation(b), s + 7, 12 * sizeof(double));
        dBodySetPosition(b, s[0], s[1], s[2]);
        dBodySetLinearVel(b, s[19], s[20], s[21]);
        dBodySetAngularVel(b, s[22], s[23], s[24]);
        dBodyEnable(b);                /* the rest count starts again (odin_step.h) */
        if (s[25] == 0.0) dBodyDisable(b);
    }
}

int odin_state_vector_fault(const double *v, int size, int flags) {
    if (!(v[0] >= 0.0 && v[0] < 4294967296.0 && v[0] == floor(v[0]))) return 0;
    for (int i = 1; i < size - flags; ++i)
        if (!isfinite(v[i])) return i;
    for (int i = size - flags > 1 ? size - flags : 1; i < size; ++i)
        if (v[i] != 0.0 && v[i] != 1.0) return i;
    return -1;
}
