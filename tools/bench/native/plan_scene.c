/* Native limit for bench_plan.py: a plain ODE state propagator written directly against
 * libode, for a world of primitives (the Sphere demo's, which bench_plan.py describes from
 * the Odin Core's build of it). One propagation: put every body's state back, push the
 * robot's body with a force, collide (a hash space, up to max_contacts contact joints per
 * pair, soft with the world's ERP and CFM, friction mu), take one dWorldStep (what Odin's
 * automatic solver takes for these small islands), read every body's state. Built as a
 * shared library (gcc -O2 -DdDOUBLE -shared -fPIC ... -lode) and called through cffi from
 * the same OMPL propagator callback the Core back end serves, so that the figures compare
 * the propagators alone.
 *
 * A state is 13 doubles per body, in the order bodies were added: position (m), quaternion
 * (w, x, y, z), linear velocity (m/s), angular velocity (rad/s), world frame. */
#include <ode/ode.h>
#include <stdint.h>
#include <string.h>

#define MAX_BODIES 64
#define STATE_SIZE 13

enum { ROLE_OTHER = 0, ROLE_ROBOT = 1, ROLE_FORBIDDEN = 2 };

static dWorldID world;
static dSpaceID space;
static dJointGroupID contacts;
static dBodyID bodies[MAX_BODIES];
static int body_count;
static int max_contacts = 3;
static double contact_erp, contact_cfm, contact_mu;
static int touched_forbidden;

int ps_create(double gx, double gy, double gz, double erp, double cfm, int pair_contacts,
              double mu) {
    dInitODE2(0);
    world = dWorldCreate();
    space = dHashSpaceCreate(0);
    contacts = dJointGroupCreate(0);
    dWorldSetGravity(world, gx, gy, gz);
    dWorldSetERP(world, erp);
    dWorldSetCFM(world, cfm);
    dWorldSetContactSurfaceLayer(world, 0.001);
    contact_erp = erp;
    contact_cfm = cfm;
    contact_mu = mu;
    max_contacts = pair_contacts < 1 ? 1 : (pair_contacts > 16 ? 16 : pair_contacts);
    body_count = 0;
    return 0;
}

/* shape 1 sphere (radius), 3 box (sides), 6 plane (normal +z through pos); mass <= 0 or a
 * plane: static. Returns the body's index, -1 for static geometry, -2 when full. */
int ps_add(int shape, const double *dims, double mass, const double *pos, const double *quat,
           int role) {
    dGeomID geom;
    if (shape == 6) geom = dCreatePlane(space, 0, 0, 1, pos[2]);
    else if (shape == 1) geom = dCreateSphere(space, dims[0]);
    else geom = dCreateBox(space, dims[0], dims[1], dims[2]);
    dGeomSetData(geom, (void *)(intptr_t)role);
    if (shape == 6 || mass <= 0) {
        if (shape != 6) {
            dQuaternion q = {quat[0], quat[1], quat[2], quat[3]};
            dGeomSetPosition(geom, pos[0], pos[1], pos[2]);
            dGeomSetQuaternion(geom, q);
        }
        return -1;
    }
    if (body_count == MAX_BODIES) return -2;
    dBodyID body = dBodyCreate(world);
    dMass m;
    if (shape == 1) dMassSetSphereTotal(&m, mass, dims[0]);
    else dMassSetBoxTotal(&m, mass, dims[0], dims[1], dims[2]);
    dBodySetMass(body, &m);
    dGeomSetBody(geom, body);
    dQuaternion q = {quat[0], quat[1], quat[2], quat[3]};
    dBodySetPosition(body, pos[0], pos[1], pos[2]);
    dBodySetQuaternion(body, q);
    bodies[body_count] = body;
    return body_count++;
}

static void near(void *data, dGeomID a, dGeomID b) {
    (void)data;
    dBodyID ba = dGeomGetBody(a), bb = dGeomGetBody(b);
    if (!ba && !bb) return;
    if (ba && bb && dAreConnectedExcluding(ba, bb, dJointTypeContact)) return;
    dContactGeom found[16];
    int n = dCollide(a, b, max_contacts, found, sizeof(dContactGeom));
    if (n == 0) return;
    int ra = (int)(intptr_t)dGeomGetData(a), rb = (int)(intptr_t)dGeomGetData(b);
    if ((ra == ROLE_ROBOT && rb == ROLE_FORBIDDEN) || (rb == ROLE_ROBOT && ra == ROLE_FORBIDDEN))
        touched_forbidden = 1;
    for (int i = 0; i < n; ++i) {
        dContact c;
        memset(&c, 0, sizeof c);
        c.surface.mode = dContactSoftERP | dContactSoftCFM | dContactApprox1;
        c.surface.mu = contact_mu;
        c.surface.soft_erp = contact_erp;
        c.surface.soft_cfm = contact_cfm;
        c.geom = found[i];
        dJointAttach(dJointCreateContact(world, contacts, &c), ba, bb);
    }
}

static void put_state(const double *s) {
    for (int i = 0; i < body_count; ++i, s += STATE_SIZE) {
        dQuaternion q = {s[3], s[4], s[5], s[6]};
        dBodySetPosition(bodies[i], s[0], s[1], s[2]);
        dBodySetQuaternion(bodies[i], q);
        dBodySetLinearVel(bodies[i], s[7], s[8], s[9]);
        dBodySetAngularVel(bodies[i], s[10], s[11], s[12]);
        dBodyEnable(bodies[i]);
    }
}

void ps_read(double *s) {
    for (int i = 0; i < body_count; ++i, s += STATE_SIZE) {
        const dReal *p = dBodyGetPosition(bodies[i]), *q = dBodyGetQuaternion(bodies[i]);
        const dReal *v = dBodyGetLinearVel(bodies[i]), *w = dBodyGetAngularVel(bodies[i]);
        for (int k = 0; k < 3; ++k) { s[k] = p[k]; s[7 + k] = v[k]; s[10 + k] = w[k]; }
        for (int k = 0; k < 4; ++k) s[3 + k] = q[k];
    }
}

/* One propagation step of `step` s from state_in under `force` (N, world frame) on body
 * `robot`; writes state_out; returns 1 when the robot touched a forbidden geometry. */
int ps_propagate(const double *state_in, int robot, const double *force, double step,
                 double *state_out) {
    put_state(state_in);
    touched_forbidden = 0;
    dBodyAddForce(bodies[robot], force[0], force[1], force[2]);
    dSpaceCollide(space, 0, near);
    dWorldStep(world, step);
    dJointGroupEmpty(contacts);
    ps_read(state_out);
    return touched_forbidden;
}

int ps_body_count(void) { return body_count; }
