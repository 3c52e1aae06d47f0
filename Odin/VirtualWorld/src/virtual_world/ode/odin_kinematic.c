/* The kinematic drive's per-step work (see OdinKinematicLink in odin_step.h): forward kinematics
 * of each driven link over one step, turned into the velocities that carry the link there.
 * Quaternions are (w, x, y, z), as ODE's. */
#include "odin_step.h"

#include <math.h>

static void quaternion_multiply(double out[4], const double a[4], const double b[4]) {
    double w = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
    double x = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
    double y = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
    double z = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
    out[0] = w; out[1] = x; out[2] = y; out[3] = z;
}

static void conjugate(double out[4], const double q[4]) {
    out[0] = q[0]; out[1] = -q[1]; out[2] = -q[2]; out[3] = -q[3];
}

/* out = q v q* (q a unit quaternion); out may be v. */
static void rotate(double out[3], const double q[4], const double v[3]) {
    double p[4] = {0.0, v[0], v[1], v[2]}, qc[4], t[4];
    conjugate(qc, q);
    quaternion_multiply(t, q, p);
    quaternion_multiply(p, t, qc);
    out[0] = p[1]; out[1] = p[2]; out[2] = p[3];
}

/* A rigid pose: body position (m) and orientation. */
typedef struct { double p[3], q[4]; } Pose;

static Pose body_pose(dBodyID b) {
    Pose pose;
    const dReal *p = dBodyGetPosition(b), *q = dBodyGetQuaternion(b);
    for (int i = 0; i < 3; ++i) pose.p[i] = p[i];
    for (int i = 0; i < 4; ++i) pose.q[i] = q[i];
    return pose;
}

/* a o b: b expressed in a's frame, put in the world. */
static Pose compose(const Pose *a, const Pose *b) {
    Pose out;
    rotate(out.p, a->q, b->p);
    for (int i = 0; i < 3; ++i) out.p[i] += a->p[i];
    quaternion_multiply(out.q, a->q, b->q);
    return out;
}

static Pose inverse(const Pose *a) {
    Pose out;
    conjugate(out.q, a->q);
    rotate(out.p, out.q, a->p);
    for (int i = 0; i < 3; ++i) out.p[i] = -out.p[i];
    return out;
}

/* The joint's motion over the step in the world frame as it is now: a turn by `angle` about the
 * hinge's axis through its anchor, or a move by `angle` (m) along the slider's axis. */
static Pose joint_motion(const OdinKinematicLink *k, double amount) {
    Pose m = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0, 0.0}};
    dVector3 axis;
    if (k->joint_type == dJointTypeSlider) {
        dJointGetSliderAxis(k->joint, axis);
        for (int i = 0; i < 3; ++i) m.p[i] = axis[i] * amount;
        return m;
    }
    dVector3 anchor;
    dJointGetHingeAxis(k->joint, axis);
    dJointGetHingeAnchor(k->joint, anchor);
    double s = sin(0.5 * amount);
    m.q[0] = cos(0.5 * amount);
    for (int i = 0; i < 3; ++i) m.q[i + 1] = s * axis[i];
    double a[3] = {anchor[0], anchor[1], anchor[2]}, turned[3];
    rotate(turned, m.q, a);
    for (int i = 0; i < 3; ++i) m.p[i] = a[i] - turned[i];    /* the anchor stays */
    return m;
}

/* The angular velocity (rad/s) that turns `from` into `to` in h seconds (finite rotation). */
static void angular_velocity(double w[3], const double from[4], const double to[4], double h) {
    double inv[4], d[4];
    conjugate(inv, from);
    quaternion_multiply(d, to, inv);
    if (d[0] < 0) for (int i = 0; i < 4; ++i) d[i] = -d[i];     /* the short way round */
    double s = sqrt(d[1] * d[1] + d[2] * d[2] + d[3] * d[3]);
    double scale = s > 1e-300 ? 2.0 * atan2(s, d[0]) / (s * h) : 2.0 / h;
    for (int i = 0; i < 3; ++i) w[i] = d[i + 1] * scale;
}

void odin_kinematic_drive(OdinWorld *w, double h) {
    for (int i = 0; i < w->n_kinematic; ++i) {
        OdinKinematicLink *k = &w->kinematic[i];
        Pose now = body_pose(k->body);
        Pose motion = joint_motion(k, k->direction * h * w->motors[k->motor].speed[0]);
        Pose moved = compose(&motion, &now);
        Pose next = moved;
        if (k->parent_link >= 0) {      /* carried along by the parent's own motion */
            const OdinKinematicLink *p = &w->kinematic[k->parent_link];
            Pose parent_now = body_pose(k->parent), parent_next, parent_inv;
            for (int j = 0; j < 3; ++j) parent_next.p[j] = p->next_position[j];
            for (int j = 0; j < 4; ++j) parent_next.q[j] = p->next_quaternion[j];
            parent_inv = inverse(&parent_now);
            Pose relative = compose(&parent_inv, &moved);
            next = compose(&parent_next, &relative);
        }
        if (fabs(next.p[0]) > w->extent || fabs(next.p[1]) > w->extent ||
            fabs(next.p[2]) > w->extent || !isfinite(next.p[0] + next.p[1] + next.p[2]))
            next = now;     /* a link stops at the world's extent (no body may leave it) */
        double norm = sqrt(next.q[0] * next.q[0] + next.q[1] * next.q[1] +
                           next.q[2] * next.q[2] + next.q[3] * next.q[3]);
        for (int j = 0; j < 4; ++j) k->next_quaternion[j] = next.q[j] / norm;
        for (int j = 0; j < 3; ++j) k->next_position[j] = next.p[j];
        double omega[3];
        angular_velocity(omega, now.q, k->next_quaternion, h);
        dBodySetLinearVel(k->body, (next.p[0] - now.p[0]) / h, (next.p[1] - now.p[1]) / h,
                          (next.p[2] - now.p[2]) / h);
        dBodySetAngularVel(k->body, omega[0], omega[1], omega[2]);
    }
}

void odin_kinematic_set(dBodyID body, int on) {
    if (on) {
        dBodySetKinematic(body);
        dBodySetFiniteRotationMode(body, 1);
        dBodySetFiniteRotationAxis(body, 0, 0, 0);
        dBodySetAutoDisableFlag(body, 0);    /* a slow link still moves */
        dBodyEnable(body);
    } else {
        dBodySetDynamic(body);
        dBodySetFiniteRotationMode(body, 0);
    }
}
