/* The geometric planner's motion check in one C call (virtual_world.core.motion): whether the
 * straight segment between two control vectors is collision-free, forward kinematics included,
 * so OMPL's motion validator enters Python once per motion, not once per configuration.
 *
 * The walk is gui.planning.geometric_world's (its module docstring says why it is sound):
 * a motion whose links only translate is split in halves until each piece's swept boxes touch
 * nothing, or the piece moves no link more than the resolution and its ends are checked; any
 * other motion is walked from its start, each step as long as the links' clearances (lower
 * bounds of their distances to everything else, odin_query.c) allow, or one resolution long
 * and checked. Kinematics: each link's motion from its parent as A + sin q B + (1 - cos q) C
 * (Rodrigues' formula) for a revolute joint, A + q B for a prismatic one; a base the controls
 * move placed in its box, turned by Kautham's quaternion of three values (Kuffner's). */
#include <ode/ode.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "odin_step.h"

#define SHRINKS 4            /* halvings of a step before a resolution step */
#define PROBE_SPACING 8      /* resolutions per probe checked before a walk */
#define MAX_SWEEP_DEPTH 60   /* halvings of a translating motion (a piece of 2^-60 is a point) */
#define ORTHONORMAL_TOLERANCE 1e-6

static const double PROBES[] = {0.5, 0.25, 0.75, 0.125, 0.375, 0.625, 0.875};

/* One configuration of every robot: per robot its base (16), joints, object frames (16 per
 * link); `framed` once the frames are computed. */
typedef struct {
    double *values;
    int framed;
} Placement;

typedef struct {
    OdinMotionChecker *m;
    const double *a, *b;     /* the motion's control vectors */
    int values;              /* doubles per placement */
    double *controls;        /* scratch: a control vector */
    double *dofs;            /* scratch: one robot's normalised DOF values */
    double *chain;           /* scratch: chain frames of one robot's links */
    double *bounds;          /* scratch: ODIN_BOUND_VALUES per moved link */
    double *moves, *rest, *needed, *out;   /* scratch: one per link */
    double *obstacles, *found_obstacles, *gaps, *found_gaps;
    int *firsts;
    int *counts;             /* [configurations checked exactly, clearance queries] */
    int error;               /* 1: a configuration left the world (nothing placed) */
    double *memory;          /* the block the scratch arrays and placements are in */
    double deadline;         /* CLOCK_MONOTONIC s after which the walk gives up (0: never) */
    int timed_out;           /* the deadline passed: every query answers 0 from then on */
} Walk;

/* Whether the walk's deadline has passed, read before every query (tens of ns; one query near
 * heavy meshes can take tens of ms, and the search's time limit must hold). */
static int over(Walk *walk) {
    if (walk->timed_out) return 1;
    if (walk->deadline <= 0.0) return 0;
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    walk->timed_out = now.tv_sec + 1e-9 * now.tv_nsec >= walk->deadline;
    return walk->timed_out;
}

static int robot_values(const OdinKinematicRobot *r) {
    return 16 + r->n_joints + 16 * r->n_links;
}

static double *robot_block(const OdinMotionChecker *m, const Placement *p, int robot) {
    double *v = p->values;
    for (int i = 0; i < robot; ++i) v += robot_values(&m->robots[i]);
    return v;
}

static void mul44(const double *a, const double *b, double *out) {
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            out[4 * i + j] = a[4 * i] * b[j] + a[4 * i + 1] * b[4 + j] + a[4 * i + 2] * b[8 + j]
                             + a[4 * i + 3] * b[12 + j];
}

static double clamp01(double x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x); }

/* Kautham's SE3Conf::setCoordinates quaternion (w, x, y, z) of three values in [0, 1], as a
 * rotation matrix (3 x 3, row by row). */
static void kuffner_rotation(const double *p, double *R) {
    double r1 = sqrt(p[0]), r2 = sqrt(1.0 - p[0]);
    double t1 = 2.0 * M_PI * p[1], t2 = M_PI * p[2];
    double w = cos(t2) * r2, x = sin(t1) * r1, y = cos(t1) * r1, z = sin(t2) * r2;
    double m[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                   2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                   2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)};
    memcpy(R, m, sizeof m);
}

/* The normalised DOF values p (clamped) of robot r for the control vector c; returns whether
 * none was clamped. */
static int dof_values(const OdinKinematicRobot *r, const double *c, double *p) {
    int within = 1;
    const double *part = c + r->part_start;
    for (int d = 0; d < r->n_dofs; ++d) {
        double v = r->offset[d];
        for (int j = 0; j < r->part_len; ++j) v += r->matrix[d * r->part_len + j] * (part[j] - 0.5);
        if (!(v >= 0.0 && v <= 1.0)) within = 0;
        p[d] = clamp01(v);
    }
    return within;
}

/* Robot r's base pose and joint values for the control vector c into its block. */
static void configure_robot(const OdinKinematicRobot *r, const double *c, double *block,
                            double *p) {
    double *base = block, *joints = block + 16;
    dof_values(r, c, p);
    for (int j = 0; j < r->n_joints; ++j)
        joints[j] = r->joint_low[j] + p[r->dof_of_joint[j]] * r->joint_span[j];
    if (!r->moves_base) {
        memcpy(base, r->base_pose, 16 * sizeof(double));
        return;
    }
    const double *box = r->base_box, *home = r->base_pose;
    double position[3];
    for (int i = 0; i < 3; ++i)
        position[i] = box[2 * i] + p[i] * (box[2 * i + 1] - box[2 * i]);
    if (r->base_turns) {
        double R[9], local[16] = {0};
        kuffner_rotation(p + 3, R);
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) local[4 * i + j] = R[3 * i + j];
            local[4 * i + 3] = position[i];
        }
        local[15] = 1.0;
        mul44(home, local, base);
        return;
    }
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) base[4 * i + j] = r->base_rotation[3 * i + j];
        base[4 * i + 3] = home[4 * i] * position[0] + home[4 * i + 1] * position[1]
                          + home[4 * i + 2] * position[2] + home[4 * i + 3];
    }
    base[12] = base[13] = base[14] = 0.0;
    base[15] = 1.0;
}

static void configure(Walk *walk, const double *c, Placement *p) {
    OdinMotionChecker *m = walk->m;
    for (int i = 0; i < m->n_robots; ++i)
        configure_robot(&m->robots[i], c, robot_block(m, p, i), walk->dofs);
    p->framed = 0;
}

/* The placement of the point t of the motion. */
static void configure_at(Walk *walk, double t, Placement *p) {
    for (int i = 0; i < walk->m->size; ++i)
        walk->controls[i] = walk->a[i] + t * (walk->b[i] - walk->a[i]);
    configure(walk, walk->controls, p);
}

static void robot_frames(const OdinKinematicRobot *r, double *block, double *chain) {
    const double *base = block, *joints = block + 16;
    double *frames = block + 16 + r->n_joints;
    for (int i = 0; i < r->n_links; ++i) {
        double local[16];
        double q = 0.0;
        for (int j = 0; j < r->n_joints; ++j)
            if (r->joint_link[j] == i) q = joints[j];
        double first = r->rotational[i] ? sin(q) : q;
        double second = r->rotational[i] ? 1.0 - cos(q) : 0.0;
        const double *A = r->fixed_part + 16 * i, *B = r->first_part + 16 * i,
                     *C = r->second_part + 16 * i;
        for (int k = 0; k < 16; ++k) local[k] = A[k] + first * B[k] + second * C[k];
        mul44(r->parent[i] < 0 ? base : chain + 16 * r->parent[i], local, chain + 16 * i);
        mul44(chain + 16 * i, r->offsets + 16 * i, frames + 16 * i);
    }
}

static void frames(Walk *walk, Placement *p) {
    if (p->framed) return;
    OdinMotionChecker *m = walk->m;
    for (int i = 0; i < m->n_robots; ++i)
        robot_frames(&m->robots[i], robot_block(m, p, i), walk->chain);
    p->framed = 1;
}

static const double *frame_of(const OdinMotionChecker *m, const Placement *p, int robot, int link) {
    const OdinKinematicRobot *r = &m->robots[robot];
    return robot_block(m, p, robot) + 16 + r->n_joints + 16 * link;
}

/* rad: the angle of the rotation from a's to b's (4 x 4 poses). */
static double angle_between(const double *a, const double *b) {
    double trace = 0.0;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) trace += a[4 * k + i] * b[4 * k + i];
    double cosine = (trace - 1.0) / 2.0;
    return acos(cosine < -1.0 ? -1.0 : (cosine > 1.0 ? 1.0 : cosine));
}

/* Per link of every robot (m): no point of it moves farther than this from p to q. */
static void link_bounds(const OdinMotionChecker *m, const Placement *p, const Placement *q,
                        double *out) {
    for (int r = 0; r < m->n_robots; ++r) {
        const OdinKinematicRobot *robot = &m->robots[r];
        const double *bp = robot_block(m, p, r), *bq = robot_block(m, q, r);
        double moved = 0.0, turned = 0.0;
        if (robot->moves_base) {
            double d[3] = {bq[3] - bp[3], bq[7] - bp[7], bq[11] - bp[11]};
            moved = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            turned = angle_between(bp, bq);
        }
        for (int i = 0; i < robot->n_links; ++i) {
            double bound = 0.0;
            for (int j = 0; j < robot->n_joints; ++j)
                bound += robot->arms[i * robot->n_joints + j] * fabs(bq[16 + j] - bp[16 + j]);
            if (robot->moves_base) bound = bound + moved + turned * robot->reaches[i];
            *out++ = bound;
        }
    }
}

static int total_links(const OdinMotionChecker *m) {
    int n = 0;
    for (int r = 0; r < m->n_robots; ++r) n += m->robots[r].n_links;
    return n;
}

static double largest(const double *v, int n) {
    double best = 0.0;
    for (int i = 0; i < n; ++i) if (v[i] > best) best = v[i];
    return best;
}

static double max_bound(Walk *walk, const Placement *p, const Placement *q) {
    link_bounds(walk->m, p, q, walk->rest);
    return largest(walk->rest, total_links(walk->m));
}

/* Whether a frame may be shown to ODE: finite, within the world's extent, its rotation
 * orthonormal (ODE makes a quaternion of it). */
static int frame_sane(const double *T, double extent) {
    for (int i = 0; i < 3; ++i)
        if (!(fabs(T[4 * i + 3]) <= extent)) return 0;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) {
            double dot = T[4 * i] * T[4 * k] + T[4 * i + 1] * T[4 * k + 1]
                         + T[4 * i + 2] * T[4 * k + 2];
            if (!(fabs(dot - (i == k)) <= ORTHONORMAL_TOLERANCE)) return 0;
        }
    return 1;
}

/* Robot r's link frame at p when ODE may be shown it (frame_sane); else NULL, walk->error set. */
static const double *checked_frame(Walk *walk, const Placement *p, int r, int link) {
    const double *T = frame_of(walk->m, p, r, link);
    if (frame_sane(T, walk->m->world->extent)) return T;
    walk->error = 1;
    return NULL;
}

/* Whether no moved link touches anything at p (the step's pairs); walk->error when a frame is
 * not sane (nothing placed). */
static int valid(Walk *walk, Placement *p) {
    OdinMotionChecker *m = walk->m;
    if (over(walk)) return 0;   /* the search is over: the motion is not taken */
    frames(walk, p);
    walk->counts[0]++;
    int n = 0;
    for (int r = 0; r < m->n_robots; ++r) {
        const OdinKinematicRobot *robot = &m->robots[r];
        for (int k = 0; k < robot->n_moved; ++k, ++n) {
            const double *T = checked_frame(walk, p, r, robot->moved[k]), *com = m->com + 3 * n;
            if (!T) return 0;
            double *pose = walk->bounds + 12 * n;
            for (int i = 0; i < 3; ++i) {
                pose[i] = T[4 * i + 3] + T[4 * i] * com[0] + T[4 * i + 1] * com[1]
                          + T[4 * i + 2] * com[2];
                for (int j = 0; j < 3; ++j) pose[3 + 3 * i + j] = T[4 * i + j];
            }
        }
    }
    odin_place_bodies(m->bodies, n, walk->bounds);
    dGeomID hit[2];
    return !odin_geoms_touching(m->world, m->geoms, m->n_geoms, hit);
}

static void transform(const double *T, const double *v, double *out) {
    for (int i = 0; i < 3; ++i)
        out[i] = T[4 * i] * v[0] + T[4 * i + 1] * v[1] + T[4 * i + 2] * v[2] + T[4 * i + 3];
}

static void rotate(const double *T, const double *v, double *out) {
    for (int i = 0; i < 3; ++i)
        out[i] = T[4 * i] * v[0] + T[4 * i + 1] * v[1] + T[4 * i + 2] * v[2];
}

/* The link's bound (its box or its capsule, whichever holds it more tightly) at frame T. */
static void world_bound(const OdinKinematicRobot *r, int link, const double *T, double *out) {
    memset(out, 0, ODIN_BOUND_VALUES * sizeof(double));
    if (!r->boxed[link]) {
        const double *capsule = r->capsules + 7 * link;
        out[0] = ODIN_BOUND_CAPSULE;
        transform(T, capsule, out + 1);
        transform(T, capsule + 3, out + 4);
        out[7] = capsule[6];
        return;
    }
    const double *box = r->boxes + 15 * link;
    out[0] = ODIN_BOUND_BOX;
    transform(T, box, out + 1);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            out[4 + 3 * i + j] = T[4 * i] * box[3 + j] + T[4 * i + 1] * box[6 + j]
                                 + T[4 * i + 2] * box[9 + j];
    memcpy(out + 13, box + 12, 3 * sizeof(double));
}

/* m: the distance between segments p (a, b) and q (a, b), by their closest points (Ericson,
 * Real-Time Collision Detection, 5.1.9), as gui.planning.geometric_world computes it. */
static double segment_distance(const double *p, const double *q) {
    const double tiny = 1e-18;
    double d1[3], d2[3], r[3];
    for (int i = 0; i < 3; ++i) {
        d1[i] = p[3 + i] - p[i];
        d2[i] = q[3 + i] - q[i];
        r[i] = p[i] - q[i];
    }
    double a = 0, e = 0, f = 0, c = 0, b = 0;
    for (int i = 0; i < 3; ++i) {
        a += d1[i] * d1[i]; e += d2[i] * d2[i]; f += d2[i] * r[i]; c += d1[i] * r[i];
        b += d1[i] * d2[i];
    }
    double denominator = a * e - b * b;
    double s = denominator > tiny ? clamp01((b * f - c * e) / denominator) : 0.0;
    double t = e > tiny ? (b * s + f) / e : 0.0;
    if (t < 0.0) s = a > tiny ? clamp01(-c / a) : 0.0;
    if (t > 1.0) s = a > tiny ? clamp01((b - c) / a) : 0.0;
    if (e <= tiny) s = a > tiny ? clamp01(-c / a) : 0.0;
    t = clamp01(t);
    double sum = 0.0;
    for (int i = 0; i < 3; ++i) {
        double d = (p[i] + d1[i] * s) - (q[i] + d2[i] * t);
        sum += d * d;
    }
    return sqrt(sum);
}

/* The clearances at p (gui.planning.geometric_world.GeometricWorld.clearances): per link
 * into walk->obstacles (inf for a link no control moves), per pair into walk->gaps; `needed`
 * (per link): no tier beyond the smallest reaching it is asked. 0: a frame is not sane. */
static int clearances(Walk *walk, Placement *p, const double *needed) {
    OdinMotionChecker *m = walk->m;
    if (over(walk)) return 0;
    frames(walk, p);
    walk->counts[1]++;
    int n = 0, base = 0;
    for (int r = 0; r < m->n_robots; ++r) {
        const OdinKinematicRobot *robot = &m->robots[r];
        for (int k = 0; k < robot->n_moved; ++k, ++n) {
            int link = robot->moved[k];
            const double *T = checked_frame(walk, p, r, link);
            if (!T) return 0;
            world_bound(robot, link, T, walk->bounds + ODIN_BOUND_VALUES * n);
            int reaching = 0;   /* tiers (descending) at least the need */
            while (reaching < m->n_tiers && m->tiers[reaching] >= needed[base + link]) ++reaching;
            walk->firsts[n] = reaching > 0 ? reaching - 1 : 0;
        }
        base += robot->n_links;
    }
    int links = total_links(m);
    for (int i = 0; i < links; ++i) walk->obstacles[i] = INFINITY;
    odin_bounds_clearance(m->world, walk->bounds, n, m->tiers, m->n_tiers, m->apart, m->n_apart,
                          walk->firsts, m->hints, walk->out);
    n = 0, base = 0;
    for (int r = 0; r < m->n_robots; ++r) {
        const OdinKinematicRobot *robot = &m->robots[r];
        for (int k = 0; k < robot->n_moved; ++k)
            walk->obstacles[base + robot->moved[k]] = walk->out[n++];
        base += robot->n_links;
    }
    for (int i = 0; i < m->n_pairs; ++i) {
        double capsules[2][7];
        for (int side = 0; side < 2; ++side) {
            int link = m->pairs[2 * i + side], r = 0;
            while (link >= m->robots[r].n_links) link -= m->robots[r++].n_links;
            const double *capsule = m->robots[r].capsules + 7 * link, *T = frame_of(m, p, r, link);
            transform(T, capsule, capsules[side]);
            transform(T, capsule + 3, capsules[side] + 3);
            capsules[side][6] = capsule[6];
        }
        double gap = segment_distance(capsules[0], capsules[1]) - capsules[0][6] - capsules[1][6];
        walk->gaps[i] = gap > 0.0 ? gap : 0.0;
    }
    return 1;
}

/* -- the walk of a translating motion ---------------------------------------------------- */

/* Whether the robot turns no link from p to q (no revolute joint moves, the base's rotation
 * stays). */
static int robot_translates(const OdinKinematicRobot *r, const double *bp, const double *bq) {
    for (int j = 0; j < r->n_joints; ++j)
        if (r->rotational[r->joint_link[j]] && bp[16 + j] != bq[16 + j]) return 0;
    if (r->moves_base)
        for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 3; ++k)
                if (bp[4 * i + k] != bq[4 * i + k]) return 0;
    return 1;
}

static int sweeps(Walk *walk, const Placement *here, const Placement *end) {
    OdinMotionChecker *m = walk->m;
    if (m->n_pairs) return 0;
    for (int r = 0; r < m->n_robots; ++r) {
        const OdinKinematicRobot *robot = &m->robots[r];
        if (!robot_translates(robot, robot_block(m, here, r), robot_block(m, end, r))
            || !dof_values(robot, walk->a, walk->dofs) || !dof_values(robot, walk->b, walk->dofs))
            return 0;
    }
    return 1;
}

/* Columns u (the motion's direction), v (the box axis most across it, made square to it),
 * u x v, row by row into out; the box's axes when the motion is nil. */
static void motion_axes(const double *motion, const double *axes, double *out) {
    double length = sqrt(motion[0] * motion[0] + motion[1] * motion[1] + motion[2] * motion[2]);
    if (length == 0.0) { memcpy(out, axes, 9 * sizeof(double)); return; }
    double u[3] = {motion[0] / length, motion[1] / length, motion[2] / length}, v[3], w[3];
    int across = 0;
    double least = INFINITY;
    for (int k = 0; k < 3; ++k) {
        double dot = fabs(u[0] * axes[k] + u[1] * axes[3 + k] + u[2] * axes[6 + k]);
        if (dot < least) { least = dot; across = k; }
    }
    double along = 0.0;
    for (int i = 0; i < 3; ++i) along += axes[3 * i + across] * u[i];
    double norm = 0.0;
    for (int i = 0; i < 3; ++i) { v[i] = axes[3 * i + across] - along * u[i]; norm += v[i] * v[i]; }
    norm = sqrt(norm);
    for (int i = 0; i < 3; ++i) v[i] /= norm;
    w[0] = u[1] * v[2] - u[2] * v[1];
    w[1] = u[2] * v[0] - u[0] * v[2];
    w[2] = u[0] * v[1] - u[1] * v[0];
    for (int i = 0; i < 3; ++i) { out[3 * i] = u[i]; out[3 * i + 1] = v[i]; out[3 * i + 2] = w[i]; }
}

/* The box (a bound) holding a link's box at frames Ta and Tb and all between (straight
 * translation): the smaller of the boxes along the link's axes and along the motion. */
static void swept_box(const OdinKinematicRobot *r, int link, const double *Ta, const double *Tb,
                      double *out) {
    const double *box = r->boxes + 15 * link, *B = box + 3, *half = box + 12;
    double points[16][3], candidates[2][9], motion[3];
    for (int side = 0; side < 2; ++side) {
        const double *T = side ? Tb : Ta;
        double R[9], centre[3];
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                R[3 * i + j] = T[4 * i] * B[j] + T[4 * i + 1] * B[3 + j] + T[4 * i + 2] * B[6 + j];
        if (!side) memcpy(candidates[0], R, sizeof R);
        transform(T, box, centre);
        for (int c = 0; c < 8; ++c) {
            double local[3] = {(c & 4 ? 1 : -1) * half[0], (c & 2 ? 1 : -1) * half[1],
                               (c & 1 ? 1 : -1) * half[2]};
            for (int i = 0; i < 3; ++i)
                points[8 * side + c][i] = R[3 * i] * local[0] + R[3 * i + 1] * local[1]
                                          + R[3 * i + 2] * local[2] + centre[i];
        }
    }
    for (int i = 0; i < 3; ++i) motion[i] = Tb[4 * i + 3] - Ta[4 * i + 3];
    motion_axes(motion, candidates[0], candidates[1]);
    double best_volume = INFINITY, low[3], high[3];
    const double *best = candidates[0];
    for (int k = 0; k < 2; ++k) {
        const double *axes = candidates[k];
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int n = 0; n < 16; ++n)
            for (int j = 0; j < 3; ++j) {
                double x = points[n][0] * axes[j] + points[n][1] * axes[3 + j]
                           + points[n][2] * axes[6 + j];
                if (x < lo[j]) lo[j] = x;
                if (x > hi[j]) hi[j] = x;
            }
        double volume = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
        if (volume < best_volume) {
            best_volume = volume;
            best = axes;
            memcpy(low, lo, sizeof lo);
            memcpy(high, hi, sizeof hi);
        }
    }
    memset(out, 0, ODIN_BOUND_VALUES * sizeof(double));
    out[0] = ODIN_BOUND_BOX;
    for (int i = 0; i < 3; ++i) {
        out[1 + i] = 0.0;
        for (int j = 0; j < 3; ++j) out[1 + i] += best[3 * i + j] * (low[j] + high[j]) / 2;
    }
    memcpy(out + 4, best, 9 * sizeof(double));
    for (int j = 0; j < 3; ++j) out[13 + j] = (high[j] - low[j]) / 2;
}

/* Whether nothing is in what the moved links sweep from p to q. */
static int swept_free(Walk *walk, Placement *p, Placement *q) {
    OdinMotionChecker *m = walk->m;
    if (over(walk)) return 0;
    frames(walk, p);
    frames(walk, q);
    walk->counts[1]++;
    int n = 0;
    for (int r = 0; r < m->n_robots; ++r) {
        const OdinKinematicRobot *robot = &m->robots[r];
        for (int k = 0; k < robot->n_moved; ++k, ++n) {
            int link = robot->moved[k];
            const double *Ta = checked_frame(walk, p, r, link);
            const double *Tb = checked_frame(walk, q, r, link);
            if (!Ta || !Tb) return 0;
            swept_box(robot, link, Ta, Tb, walk->bounds + ODIN_BOUND_VALUES * n);
            walk->firsts[n] = 0;
        }
    }
    odin_bounds_clearance(m->world, walk->bounds, n, &m->sweep_gap, 1, m->apart, m->n_apart,
                          walk->firsts, m->sweep_hints, walk->out);
    for (int i = 0; i < n; ++i) if (!(walk->out[i] > 0.0)) return 0;
    return 1;
}

/* The pieces of a translating motion from t0 (placement p) to t1 (q), from the start on:
 * each free when its sweep is, or when it moves no link more than the resolution and its ends
 * are valid (*checked: the last point found valid, not checked again). */
static int sweep_valid(Walk *walk, double t0, Placement *p, double t1, Placement *q,
                       Placement *spare, int depth, double *checked) {
    if (swept_free(walk, p, q)) return 1;
    if (walk->error || walk->timed_out) return 0;
    if (max_bound(walk, p, q) <= walk->m->resolution) {
        if (t0 != 0.0 && t0 != *checked && !valid(walk, p)) return 0;
        if (t1 != 1.0 && !valid(walk, q)) return 0;
        *checked = t1;
        return 1;
    }
    if (depth >= MAX_SWEEP_DEPTH) return 0;     /* not shown free: not taken */
    double middle = (t0 + t1) / 2;
    Placement *between = spare;
    configure_at(walk, middle, between);
    return sweep_valid(walk, t0, p, middle, between, spare + 1, depth + 1, checked)
           && sweep_valid(walk, middle, between, t1, q, spare + 1, depth + 1, checked);
}

/* -- the walk of any other motion --------------------------------------------------------- */

static int probes_valid(Walk *walk, Placement *here, Placement *end, Placement *spare) {
    if (!valid(walk, end)) return 0;
    double resolutions = max_bound(walk, here, end) / walk->m->resolution;
    int count = (int)floor(resolutions / PROBE_SPACING);
    if (count > 7) count = 7;
    for (int i = 0; i < count; ++i) {
        configure_at(walk, PROBES[i], spare);
        if (!valid(walk, spare)) return 0;
    }
    return 1;
}

/* The first point after t that motion_points would place (each link within the resolution):
 * its fraction of the rest of the motion. */
static double resolution_fraction(Walk *walk, double t, Placement *start, Placement *point) {
    OdinMotionChecker *m = walk->m;
    double f = 1.0;
    configure_at(walk, t, start);
    for (int guard = 0; guard < 64; ++guard) {
        configure_at(walk, t + (1.0 - t) * f, point);
        double bound = max_bound(walk, start, point);
        if (bound <= m->resolution) break;
        f /= ceil(bound / m->resolution);
    }
    return f;
}

static int stale(const Walk *walk, int links, int pairs) {
    for (int i = 0; i < links; ++i)
        if (walk->obstacles[i] < walk->found_obstacles[i] / 2) return 1;
    for (int i = 0; i < pairs; ++i)
        if (walk->gaps[i] < walk->found_gaps[i] / 2) return 1;
    return 0;
}

/* One step of the walk from t (placement here) toward the end: the farthest point (into
 * `there`) each link reaches within its clearance or the resolution; *unproven when it must be
 * checked. Returns t'. */
static double advance(Walk *walk, double t, Placement *here, Placement *end, Placement *there,
                      Placement *spare, int *unproven) {
    OdinMotionChecker *m = walk->m;
    int links = total_links(m);
    double res = m->resolution;
    link_bounds(m, here, end, walk->rest);
    double fraction = 1.0;
    for (int i = 0; i < links; ++i) {
        double allowed = walk->obstacles[i] > res ? walk->obstacles[i] : res;
        double ratio = allowed / walk->rest[i];         /* rest 0: inf */
        if (ratio < fraction) fraction = ratio;
    }
    for (int i = 0; i < m->n_pairs; ++i) {
        double allowed = walk->gaps[i] > res ? walk->gaps[i] : res;
        double ratio = allowed / (walk->rest[m->pairs[2 * i]] + walk->rest[m->pairs[2 * i + 1]]);
        if (ratio < fraction) fraction = ratio;
    }
    for (int shrink = 0; shrink <= SHRINKS; ++shrink) {
        double t_next = fraction >= 1.0 ? 1.0 : t + (1.0 - t) * fraction;
        if (t_next >= 1.0) {
            memcpy(there->values, end->values, walk->values * sizeof(double));
            there->framed = end->framed;
        } else {
            configure_at(walk, t_next, there);
        }
        link_bounds(m, here, there, walk->moves);
        int fits = 1, beyond = 0;
        for (int i = 0; i < links && fits; ++i) {
            double allowed = walk->obstacles[i] > res ? walk->obstacles[i] : res;
            if (walk->moves[i] > allowed) fits = 0;
            if (walk->moves[i] > walk->obstacles[i]) beyond = 1;
        }
        for (int i = 0; i < m->n_pairs && fits; ++i) {
            double together = walk->moves[m->pairs[2 * i]] + walk->moves[m->pairs[2 * i + 1]];
            double allowed = walk->gaps[i] > res ? walk->gaps[i] : res;
            if (together > allowed) fits = 0;
            if (together > walk->gaps[i]) beyond = 1;
        }
        if (fits) {
            *unproven = beyond;
            return t_next;
        }
        fraction /= 2.0;
    }
    double t_next = t + (1.0 - t) * resolution_fraction(walk, t, spare, there);
    configure_at(walk, t_next, there);
    link_bounds(m, here, there, walk->moves);
    *unproven = 1;
    return t_next;
}

static int clearance_walk(Walk *walk, Placement *here, Placement *end, Placement *spare) {
    OdinMotionChecker *m = walk->m;
    int links = total_links(m), have_budget = 0;
    double t = 0.0;
    while (t < 1.0) {
        if (!have_budget || stale(walk, links, m->n_pairs)) {
            link_bounds(m, here, end, walk->needed);
            if (!clearances(walk, here, walk->needed)) return 0;
            memcpy(walk->found_obstacles, walk->obstacles, links * sizeof(double));
            memcpy(walk->found_gaps, walk->gaps, m->n_pairs * sizeof(double));
            have_budget = 1;
        }
        int unproven = 0;
        Placement *there = spare;
        double t_next = advance(walk, t, here, end, there, spare + 1, &unproven);
        if (!(t_next > t)) return 0;            /* no progress (rounding): not shown free */
        if (unproven && t_next < 1.0 && !valid(walk, there)) return 0;
        for (int i = 0; i < links; ++i) {
            double left = walk->obstacles[i] - walk->moves[i];
            walk->obstacles[i] = left > 0.0 ? left : 0.0;
        }
        for (int i = 0; i < m->n_pairs; ++i) {
            double left = walk->gaps[i] - walk->moves[m->pairs[2 * i]]
                          - walk->moves[m->pairs[2 * i + 1]];
            walk->gaps[i] = left > 0.0 ? left : 0.0;
        }
        /* here <- there (the placements swap buffers) */
        double *values = here->values;
        here->values = there->values;
        here->framed = there->framed;
        there->values = values;
        t = t_next;
    }
    return 1;
}

/* The walk's scratch memory (one block) and its `placements` placements (pool); 0 when out of
 * memory. */
static int walk_begin(Walk *walk, OdinMotionChecker *m, const double *a, const double *b,
                      int *counts, Placement *pool, int placements) {
    int links = total_links(m), values = 0, dofs = 0;
    for (int r = 0; r < m->n_robots; ++r) {
        values += robot_values(&m->robots[r]);
        if (m->robots[r].n_dofs > dofs) dofs = m->robots[r].n_dofs;
    }
    int scratch_links = links + 2 * m->n_pairs;
    /* every value is written before it is read: no need to clear the block */
    double *memory = malloc(((size_t)placements * values + (size_t)m->size + (size_t)dofs
                             + (size_t)16 * links + (size_t)ODIN_BOUND_VALUES * links
                             + (size_t)9 * scratch_links) * sizeof(double));
    int *firsts = malloc(((size_t)links + 1) * sizeof(int));
    if (!memory || !firsts) { free(memory); free(firsts); return 0; }
    double *cursor = memory;
    for (int i = 0; i < placements; ++i, cursor += values) {
        pool[i].values = cursor;
        pool[i].framed = 0;
    }
    *walk = (Walk){.m = m, .a = a, .b = b, .counts = counts, .firsts = firsts, .values = values};
    walk->controls = cursor; cursor += m->size;
    walk->dofs = cursor; cursor += dofs;
    walk->chain = cursor; cursor += 16 * links;
    walk->bounds = cursor; cursor += ODIN_BOUND_VALUES * links;
    double **arrays[] = {&walk->moves, &walk->rest, &walk->needed, &walk->out, &walk->obstacles,
                         &walk->found_obstacles, &walk->gaps, &walk->found_gaps};
    for (int i = 0; i < 8; ++i, cursor += scratch_links) *arrays[i] = cursor;
    walk->memory = memory;
    return 1;
}

static void walk_end(Walk *walk) {
    free(walk->memory);
    free(walk->firsts);
}

static int finite_controls(const OdinMotionChecker *m, const double *c) {
    for (int i = 0; i < m->size; ++i) if (!isfinite(c[i])) return 0;
    return 1;
}

int odin_motion_valid(OdinMotionChecker *m, const double *a, const double *b, double deadline,
                      int *counts) {
    if (!finite_controls(m, a) || !finite_controls(m, b)) return -3;
    Walk walk;
    Placement pool[MAX_SWEEP_DEPTH + 8];
    if (!walk_begin(&walk, m, a, b, counts, pool, MAX_SWEEP_DEPTH + 8)) return -2;
    walk.deadline = deadline;
    Placement *here = &pool[0], *end = &pool[1];
    configure(&walk, a, here);
    configure(&walk, b, end);
    int answer;
    if (sweeps(&walk, here, end)) {
        double checked = 0.0;
        answer = valid(&walk, end)
                 && sweep_valid(&walk, 0.0, here, 1.0, end, &pool[2], 0, &checked);
    } else {
        answer = probes_valid(&walk, here, end, &pool[2])
                 && clearance_walk(&walk, here, end, &pool[2]);
    }
    walk_end(&walk);
    return walk.error ? -1 : answer;
}

int odin_configuration_valid(OdinMotionChecker *m, const double *c, int *counts) {
    if (!finite_controls(m, c)) return -3;
    Walk walk;
    Placement pool[1];
    if (!walk_begin(&walk, m, c, c, counts, pool, 1)) return -2;
    configure(&walk, c, &pool[0]);
    int answer = valid(&walk, &pool[0]);
    walk_end(&walk);
    return walk.error ? -1 : answer;
}
