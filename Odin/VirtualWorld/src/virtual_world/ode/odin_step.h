/* Odin's per-step C code, compiled into the _odin_ode extension.
 *
 * One OdinWorld (allocated by Python with ffi.new, so Python owns its memory) gathers what the
 * hot loop needs: the ODE world, space (broad phase) and contact group, the contact settings,
 * and arrays of persistent body forces, joint forces and motor goals that Python rebuilds when
 * they change.
 * odin_world_step() runs the whole count-loop (collide, forces, motors, step, empty contacts) in
 * C; nothing is created or destroyed in it except contact joints in the contact group.
 * The only memory this file allocates is the collision-record buffer (odin_world_free_buffers).
 */
#ifndef ODIN_STEP_H
#define ODIN_STEP_H
#include <ode/ode.h>
#include <stdint.h>

#define ODIN_MAX_CONTACTS 64   /* upper bound for max_contacts per pair */
#define ODIN_RECORD_POINTS 8   /* contact points kept per recorded pair */

/* A persistent force or torque on a body (thesis 5.4.2); re-applied before every step. */
typedef struct OdinBodyForce {
    dBodyID body;
    int torque;              /* 0 force, 1 torque */
    int vector_in_body;      /* vector given in the body frame */
    int at_point;            /* force applied at `point` instead of the centre of mass */
    int point_in_body;       /* point given in the body frame */
    double vector[3];
    double point[3];
} OdinBodyForce;

/* A persistent force/torque on a joint (thesis 5.4.3); `type` is the ODE dJointType. */
typedef struct OdinJointForce {
    dJointID joint;
    int type;
    double magnitude[3];
} OdinJointForce;

/* A motor goal: speeds of an amotor (kind 0) or lmotor (kind 1), set before every step. In
 * servo mode (servo 1) the speed of each axis is computed before every step from a position
 * target instead: v = clamp(target_rate + gain (target - q), +-max_speed), applied with the
 * motor's force limit, where q is the driven joint's value on that axis (joint_value) times its
 * sign; target and position are in those signed units. ODE reads a hinge's angle in [-pi, pi]:
 * a hinge without both stops inside that range (a joint that turns past +-pi) takes the turn
 * of its angle nearest the servo's last reading, or its target at the first step after the
 * servo was set (`read` 0), so a path through +-pi is followed, not unwound. */
typedef struct OdinMotorGoal {
    dJointID motor;
    int kind;
    int naxes;
    double velocity[3];
    int servo;
    dJointID joint;          /* the joint the motor drives */
    int joint_type;          /* its ODE dJointType */
    int component[3];        /* per axis: which of the joint's values (JOINT_STATE_AXES) */
    double sign[3];          /* +1, or -1 where that value moves against the motor's speed */
    double target[3];        /* rad or m */
    double target_rate[3];   /* rad/s or m/s: feed-forward */
    double gain[3];          /* 1/s */
    double max_speed[3];     /* rad/s or m/s */
    double position[3];      /* out: the joint's value when the last step began */
    double speed[3];         /* out: the speed commanded for the last step (rad/s or m/s): the
                                goal, or the servo's clamped law */
    int read;                /* 1 once the servo has read its joint since it was last set */
} OdinMotorGoal;

/* A link under the kinematic drive (virtual_world.core.kinematic): a kinematic body whose hinge
 * or slider to its parent moves at exactly the speed its motor commands (OdinMotorGoal.speed,
 * the goal or the servo's law), whatever it meets. Before every step, parents first, the link's
 * pose at the step's end is found by forward kinematics: its pose relative to its parent's,
 * turned about (hinge) or moved along (slider) the joint's axis by direction x h x speed, on
 * the parent's pose at the step's end; the body then gets the linear and angular velocity that
 * carry it there in the step (ODE integrates a kinematic body by its velocities, with finite
 * rotation: exact to rounding). So contacts and the joints to dynamic bodies see the motion and
 * no pose is ever written. Each step starts from the present poses: nothing else is state. A
 * link whose pose at the step's end would leave the world's extent stays where it is. */
typedef struct OdinKinematicLink {
    dBodyID body;
    dBodyID parent;          /* the parent's body; NULL: the static world */
    int parent_link;         /* the parent's index in the array (before this one); -1: the
                                parent is not driven (the world or a fixed body: it stays put) */
    int motor;               /* the slot of the joint's motor in OdinWorld.motors */
    dJointID joint;          /* the link's joint to its parent */
    int joint_type;          /* dJointTypeHinge or dJointTypeSlider */
    double direction;        /* +1: the link is the joint's ODE body 1 (the joint's value grows
                                as it turns or slides along the axis); -1: its body 2 */
    double next_position[3]; /* internal: the pose at the step's end (body position, m) */
    double next_quaternion[4];
} OdinKinematicLink;

/* What every geom's data (dGeomSetData) points at; Python allocates it with the geom and keeps
 * it alive as long as the geom. serial: the geom's number in its scene, given in creation order,
 * which orders colliding pairs (and so contact joints) the same way whatever the geoms' memory
 * addresses are. tag: two geoms with the same non-zero tag never collide (an entity without
 * internal collisions). */
typedef struct OdinGeomInfo {
    long serial;
    long tag;
    /* the surface's contact properties (odin_common.specs.Surface); a flag 0: the world's */
    int has_friction, has_friction2, has_bounce, has_softness;
    double mu;               /* dInfinity allowed */
    double mu2;
    double fdir[3];          /* unit, the geom's own frame: the direction of mu2 */
    double bounce, bounce_vel;
    double kp, kd;           /* N/m, N s/m */
} OdinGeomInfo;

/* A colliding pair found in one collide pass, its contacts at contacts[first .. first + n). */
typedef struct OdinPair {
    dGeomID g1, g2;          /* in serial order */
    uint64_t key;            /* serial of g1 << 32 | serial of g2: the order of contacts */
    int first, n;
    int record;              /* its collision record (index), or -1 */
} OdinPair;

/* A body the divergence guard found gone wrong after a step (and parked): reason 1 a value not
 * finite, 2 too fast (m/s), 3 spinning too fast (rad/s), 4 beyond the world's extent (m);
 * value: what broke the bound; its state as the step left it. */
typedef struct OdinDivergence {
    dBodyID body;
    int reason;
    double value;
    double position[3], velocity[3], angular[3];
    long step;
} OdinDivergence;

/* A pair of geoms found colliding (g1 the lower serial); depth is the deepest ODE contact depth
 * seen; first_step the world's step count when it was first seen since the records were
 * cleared; points and normals (unit: the direction the contact pushes g1) of the deepest
 * occurrence; forces (N, world: the contact's force on g1 at each point) when has_forces (the
 * contact policy's last step of a call, from ODE's joint feedback). */
typedef struct OdinCollision {
    dGeomID g1, g2;
    double depth;
    long first_step;
    int npoints;
    double points[ODIN_RECORD_POINTS][3];
    double normals[ODIN_RECORD_POINTS][3];
    double forces[ODIN_RECORD_POINTS][3];
    int has_forces;
} OdinCollision;

typedef struct OdinWorld {
    dWorldID world;
    dSpaceID space;
    dJointGroupID contact_group;
    /* contact settings */
    int max_contacts;        /* 1..ODIN_MAX_CONTACTS */
    double mu;               /* dInfinity allowed */
    double bounce;           /* 0 = no dContactBounce */
    double bounce_vel;
    int contact_less;        /* 1: record pairs only, never create contacts */
    int solver;              /* 0 QuickStep, 1 dWorldStep, 2 auto: dWorldStep while the whole
                                step has at most auto_step_rows rows (joint_rows_at_most) or an
                                island's joints alone have more (joint_rows) and the largest
                                island has at most auto_rows rows, QuickStep otherwise */
    int auto_step_rows;      /* auto's small-system bound (rows of the whole step) */
    int auto_rows;           /* auto's island bound (rows of one island) */
    int auto_articulation_rows; /* auto's articulation bound (an island's joints and motors,
                                   counted by joint_rows_at_most) */
    int last_solver;         /* output: the solver the last step used (0 or 1) */
    int island_rows;         /* output (auto): the last step's largest island's rows (0 when
                                not searched: the small-system clause held, or no awake body
                                has a non-contact joint) */
    int articulated_rows;    /* output (auto): the most rows of non-contact joints in an island */
    unsigned long rand_seed; /* the world's own state of ODE's random generator, which QuickStep
                                uses to reorder constraints: set before each QuickStep and read
                                back after, so no other world (or process history) changes it */
    /* persistent actions (arrays owned by Python) */
    OdinBodyForce *forces; int n_forces;
    OdinJointForce *joint_forces; int n_joint_forces;
    OdinMotorGoal *motors; int n_motors;
    OdinKinematicLink *kinematic; int n_kinematic;   /* parents before children */
    /* one propagation's body forces (odin_world_propagate), applied after the persistent ones;
       NULL between propagations */
    const OdinBodyForce *propagation_forces; int n_propagation_forces;
    /* outputs */
    int last_step_contacts;
    int record_every_step;   /* contact policy: record the pairs of every step, not the last */
    int pairs_only;          /* record pairs without their contact forces (no joint feedback:
                                odin_world_propagate, whose caller reads only the pairs) */
    int unordered;           /* benchmarks only: contacts made as the broad phase finds them
                                (not deterministic), to measure what the ordering costs */
    /* pairs a build left inside each other that do not collide until they have parted
     * (Core.exempt_overlaps, docs/INTERFACE.md): their keys (OdinPair.key's, serial << 32 |
     * serial), ascending, the depth (m) each may reach, and each one's state, 1.0 exempt or
     * 0.0 parted (the last values of a body state vector). A live exempt pair makes no
     * contacts and is recorded as colliding while it is deeper than exempt_depth (m) and no
     * deeper than its limit; the first step whose collide pass finds it no deeper than
     * exempt_depth (or apart) parts it for good, and it collides as any pair from the next
     * step; found deeper than its limit, it parts at once and collides in that very pass (an
     * exempt pair may move apart, never further in). Arrays owned by Python. */
    const uint64_t *exempt_keys; const double *exempt_limit; double *exempt_live; int n_exempt;
    double exempt_depth;
    unsigned char *exempt_seen;  /* internal (Python's array): met deeper in this step's pass */
    int stepping;            /* internal: 1 during a step's collide pass (only a step parts
                                exempt pairs: a collision query changes nothing) */
    /* the divergence guard: after every step each guarded body must be finite, slower than
     * max_speed (m/s) and max_spin (rad/s) and within extent (m) of the origin on every axis;
     * one that is not is parked (made kinematic, still, colliding with nothing, put back
     * within the extent) before ODE's collision code can see it, and recorded */
    dBodyID *guarded; int n_guarded;   /* the dynamic bodies (Python's array) */
    double max_speed, max_spin, extent;
    int stop_on_divergence;  /* 1: the step loop stops after a step that parked a body */
    int auto_disable;        /* ODE's auto-disabling is on: after each step the force and
                                torque accumulators of sleeping bodies are cleared */
    OdinDivergence *diverged; int n_diverged; int cap_diverged;
    long step_count;         /* steps taken since the scene began */
    int recording;           /* internal: record pairs during this collide pass */
    int record_overflow;     /* pairs dropped because memory ran out */
    OdinCollision *records; int n_records; int cap_records;
    int *table; int table_cap;   /* open addressing over records (contact-less dedupe) */
    /* internal: one collide pass's pairs and contacts, sorted before contact joints are made */
    OdinPair *pairs; OdinPair *pairs_sorted; int n_pairs; int cap_pairs;
    dContactGeom *contacts; int n_contacts; int cap_contacts;
    int buffer_overflow;     /* pairs dropped because memory ran out */
    /* internal: joint feedback of the recorded contacts of the last step of a call */
    dJointFeedback *feedback; int n_feedback; int cap_feedback;
    int *feedback_record, *feedback_point, *feedback_sign;
    /* internal: the auto solver's island search (a hash of the guarded bodies, a stack) */
    dBodyID *island_keys; int *island_index; int *island_stack; int island_cap;
} OdinWorld;


/* Makes a body a kinematic link (on 1: kinematic, finite rotation, never auto-disabled, awake)
 * or dynamic again (on 0: its mass back, infinitesimal rotation; the guard's auto-disable sync
 * sets its flag). */
void odin_kinematic_set(dBodyID body, int on);
/* Internal (odin_kinematic.c): the kinematic links' velocities for a step of h seconds. */
void odin_kinematic_drive(OdinWorld *w, double h);

/* Runs `count` steps of `h` seconds; returns the steps taken (fewer when the guard parked a
 * body and stop_on_divergence is set). */
int odin_world_step(OdinWorld *w, double h, int count);
/* ODE's auto-disabling flag is each body's own, copied from the world's when the body is made:
 * sets every guarded body's to auto_disable (after the flag or the guarded bodies changed). */
void odin_world_sync_auto_disable(OdinWorld *w);
/* Wakes every guarded body (dBodyEnable: its rest count starts again): a request changed the
 * world, and a sleeping body must meet the change as an awake one would. */
void odin_world_wake(OdinWorld *w);
/* Starts every guarded body's rest count again, sleepers staying asleep. ODE keeps the count
 * where no API reads it, so a snapshot cannot hold it: Save State restarts it here and putting
 * a state back restarts it (odin_write_body_states), and stepping on from either is the same. */
void odin_world_restart_rest_counts(OdinWorld *w);
/* How many guarded bodies sleep now (ODE's auto-disabling). */
int odin_world_sleeping(const OdinWorld *w);
/* Forgets the divergences Python has read. */
void odin_world_clear_divergences(OdinWorld *w);
/* One planner's propagation in one call: puts back the body state vector state_in (ODE's
 * random generator state, then ODIN_BODY_STATE_SIZE values for each of the n bodies, in the
 * order of `bodies`, odin_write_body_states, then the n_exempt exempt pairs' states), forgets
 * the collision records, adds `forces` (n_forces, after the persistent ones) for this call
 * only, runs odin_world_step(w, h, count) recording every step's colliding pairs, and writes
 * the state reached into state_out (the same layout). The same ODE calls in the same order as putting the vector back, adding the
 * forces and stepping one call at a time: bit-identical states. The recorded pairs' geoms go
 * into `pairs` (odin_world_record_pairs) and *n_pairs says how many records there are; when
 * they all fit (*n_pairs <= max_pairs) the records are forgotten, otherwise they stay for
 * odin_world_record_pairs. Returns the steps taken; or, changing nothing, -1 - i when value
 * i of state_in cannot be put back (odin_state_vector_fault). */
int odin_world_propagate(OdinWorld *w, dBodyID *bodies, int n, const double *state_in,
                         const OdinBodyForce *forces, int n_forces, double h, int count,
                         double *state_out, uintptr_t *pairs, int max_pairs, int *n_pairs);
/* odin_world_propagate without reading the pairs out: the records of its steps stay in
 * w->records for the caller, who clears them (odin_plan_propagate reads them in C). */
int odin_world_propagate_records(OdinWorld *w, dBodyID *bodies, int n, const double *state_in,
                                 const OdinBodyForce *forces, int n_forces, double h, int count,
                                 double *state_out);
/* The recorded pairs' geoms (g1, g2 addresses of each record) into out, which has room for
 * 2 * max values; returns how many records there are. */
int odin_world_record_pairs(const OdinWorld *w, uintptr_t *out, int max);
/* Records the pairs touching now, without stepping and without contacts: under the contact-less
 * policy always; under the contact policy only when any_policy (a collision query). */
void odin_world_detect(OdinWorld *w, int any_policy);
/* Whether a step never collides geoms o1 and o2, whatever their poses: the same entity without
 * internal collisions, the same body (or both static), or bodies joined by a joint. */
int odin_pair_never_touches(dGeomID o1, dGeomID o2);

/* The geometric planner's queries (odin_query.c); nothing recorded, no contact made. */
/* 1 when one of the n geoms touches a geom the step may collide it with (not
 * odin_pair_never_touches), on the present poses, with that pair in hit[0], hit[1]; else 0. */
int odin_geoms_touching(OdinWorld *w, const dGeomID *geoms, int n, dGeomID *hit);
/* A bound of a link's geometry for odin_bounds_clearance: ODIN_BOUND_VALUES values, the first
 * its kind. A capsule: ODIN_BOUND_CAPSULE, end a (3), end b (3), radius (m, world), unused
 * values. A box: ODIN_BOUND_BOX, centre (3, m, world), rotation (3 x 3, row by row: its axes
 * are the columns), half sides (3, m). */
#define ODIN_BOUND_VALUES 16
#define ODIN_BOUND_CAPSULE 0
#define ODIN_BOUND_BOX 1
/* For each of the n bounds, the first of the n_tiers growths `tiers` (m, descending) by which
 * the bound (a capsule's radius + tier, a box's half sides + tier) touches none of the space's
 * geoms but the n_skip geoms of `skip` (their addresses, sorted), else 0.0, into out: each a
 * lower bound of the bound's distance to them. A geom of a class ODE has no collider with
 * both for (a cylinder, a convex) counts as touching when the boxes overlap. firsts (n): the
 * largest tier each bound is asked about is tiers[firsts[i]] (a larger clearance would be of no
 * use to the caller). hints (n): where each search starts (any index; the answer is the same),
 * written back with the answer's index (n_tiers: none) for the next query to start from. */
void odin_bounds_clearance(OdinWorld *w, const double *bounds, int n, const double *tiers,
                           int n_tiers, const uintptr_t *skip, int n_skip, const int *firsts,
                           int *hints, double *out);
/* Puts n bodies at poses (12 values each: centre of mass (3, m, world), then the rotation
 * matrix (3 x 3, row by row; orthonormal: ODE makes its quaternion of it)). */
void odin_place_bodies(dBodyID *bodies, int n, const double *poses);

/* The geometric planner's motion check (odin_motion.c). One robot's kinematics over the
 * control vector, every array row by row, poses 4 x 4 (m, rad); the links in an order where a
 * parent comes before its children. The owner (virtual_world.ode.queries.MotionQuery) keeps
 * the arrays alive and checked. */
typedef struct OdinKinematicRobot {
    int n_links, n_joints, n_dofs;  /* links; joints a control moves; normalised DOFs */
    int part_start, part_len;       /* the robot's slice of the control vector */
    const double *offset;           /* n_dofs: p = clamp(offset + matrix (c - 0.5), 0, 1) */
    const double *matrix;           /* n_dofs x part_len */
    const int *dof_of_joint;        /* n_joints: each joint's DOF */
    const double *joint_low, *joint_span;  /* n_joints: q = low + p span (rad or m) */
    const int *joint_link;          /* n_joints: each joint's link */
    int moves_base, base_turns;     /* DOFs 0-2 place the base in base_box; 3-5 turn it */
    const double *base_pose;        /* 16: the base's home (world) */
    const double *base_box;         /* 6: low, high of x, y, z in the home frame (m) */
    const double *base_rotation;    /* 9: the base's rotation when it never turns */
    const double *fixed_part, *first_part, *second_part; /* n_links x 16: A, B, C */
    const int *rotational;          /* n_links: 1 revolute (sin q, 1 - cos q), 0 (q, 0) */
    const int *parent;              /* n_links: the parent link, -1 the base */
    const double *offsets;          /* n_links x 16: each body's object frame in its link's */
    const double *arms;             /* n_links x n_joints: motion bound per unit of joint */
    const double *reaches;          /* n_links: reach from the base's origin (m) */
    const double *capsules;         /* n_links x 7: ends a, b, radius (object frame, m) */
    const double *boxes;            /* n_links x 15: centre, rotation, half sides */
    const int *boxed;               /* n_links: 1 the box bounds the link more tightly */
    const int *moved;               /* n_moved: the links a control moves, ascending */
    int n_moved;
} OdinKinematicRobot;
/* The robots and what is asked of the world: the moved links' bodies (robots in order, each
 * robot's moved links in order) with their centres of mass in the object frame (3 each) and
 * their geoms; the geoms (sorted addresses) clearances do not ask against; the clearance
 * tiers (m, descending) and one search hint per moved link (odin_bounds_clearance), those of
 * the sweep's single tier sweep_gap; the pairs of robot links (indices over the robots' links
 * end to end) that may touch; the resolution (m). */
typedef struct OdinMotionChecker {
    OdinWorld *world;
    int n_robots;
    const OdinKinematicRobot *robots;
    int size;
    dBodyID *bodies;
    const double *com;
    const dGeomID *geoms;
    int n_geoms;
    const uintptr_t *apart;
    int n_apart;
    const double *tiers;
    int n_tiers;
    int *hints;
    double sweep_gap;
    int *sweep_hints;
    const int *pairs;
    int n_pairs;
    double resolution;
} OdinMotionChecker;
/* 1 when the straight segment of the control space from a (a valid configuration) to b is
 * collision-free (odin_motion.c), 0 when not, -1 when a configuration on it puts a link beyond
 * the world's extent or a frame is not a rigid transform (nothing shown to ODE), -2 out of
 * memory, -3 a control not finite (a and b: m->size values each). deadline: CLOCK_MONOTONIC
 * seconds (Python's time.monotonic) after which the walk stops and answers 0 (0: none).
 * counts[0] += configurations checked exactly, counts[1] += clearance queries. */
int odin_motion_valid(OdinMotionChecker *m, const double *a, const double *b, double deadline,
                      int *counts);
/* The same for one configuration c: 1 when no moved link touches anything, 0 when one does,
 * -1, -2 as above; counts[0] += 1. */
int odin_configuration_valid(OdinMotionChecker *m, const double *c, int *counts);

/* A control planner's rule for its propagations (odin_plan.c): role_of_serial[s] is the role
 * of the geom of serial s (n_serials of them; a geom past them has role 0); forbidden is an
 * n_roles x n_roles table, 1 where a colliding pair of those roles makes the motion invalid;
 * `tracked` the index (in the propagation's `bodies`) of the tracked link's body, com its centre
 * of mass and offset the link's origin, both m in the body's frame; the link's origin must stay
 * within [low, high] (m, world) and the body's linear velocity within max_speed (m/s) on each
 * axis. Arrays owned by Python. */
typedef struct OdinPlanRule {
    const unsigned char *role_of_serial; long n_serials;
    const unsigned char *forbidden; int n_roles;
    int tracked;
    double com[3], offset[3], low[3], high[3];
    double max_speed;
} OdinPlanRule;
/* `count` propagations of `steps` steps of h s in a row, the first from state_in, each from the
 * state the one before reached: odin_world_propagate's ODE calls, so bit for bit those calls
 * one by one. After each, its state (size values, the body state vector's layout) goes to
 * states_out + i * stride, followed by its verdict, 1.0 when the propagation was invalid under
 * `rule` (a forbidden pair collided at one of its steps, or the tracked link ended out of its
 * bounds) and 0.0 otherwise; the tracked link's origin and velocity (odin_plan_tracked) to
 * tracked_out + 6 * i. With stop_at_invalid the row ends after its first invalid propagation.
 * Returns the propagations made; or, changing nothing, -1 - i when value i of state_in cannot be
 * put back (odin_state_vector_fault). The records are forgotten. */
int odin_plan_propagate(OdinWorld *w, dBodyID *bodies, int n, const OdinPlanRule *rule,
                        const double *state_in, const OdinBodyForce *forces, int n_forces,
                        double h, int steps, int count, int stop_at_invalid,
                        double *states_out, long stride, double *tracked_out);
/* The tracked link's origin (m, world) and its body's linear velocity (m/s, world) in the body
 * state vector `state`, into out[0..6). */
void odin_plan_tracked(const OdinPlanRule *rule, const double *state, double *out);

/* Forgets the collision records (contact-less: after a read). */
void odin_world_clear_records(OdinWorld *w);
/* Frees the record and contact buffers (close/new scene). */
void odin_world_free_buffers(OdinWorld *w);

/* Bodies' dynamic state, ODIN_BODY_STATE_SIZE doubles each: position (3, centre of mass, m),
 * quaternion (4), rotation matrix (12, ODE's 3x4), linear velocity (3, m/s), angular velocity
 * (3, rad/s), enabled (1.0 or 0.0). Written back bit for bit (odin_state.c). */
#define ODIN_BODY_STATE_SIZE 26
void odin_read_body_states(dBodyID *bodies, int n, double *out);
void odin_write_body_states(dBodyID *bodies, int n, const double *in);
/* -1 when the body state vector v (size values: ODE's random generator state, the bodies'
 * records, then `flags` exempt pairs' states) can be put back: v[0] an integer in [0, 2^32),
 * every value finite and each of the last `flags` 0.0 or 1.0; otherwise the index of the first
 * value that is not (0: the generator's state). */
int odin_state_vector_fault(const double *v, int size, int flags);

/* Vectorised read-out of geom world poses: pos (n,3), quat (n,4) wxyz. */
void odin_read_poses(dGeomID *geoms, int n, double *pos, double *quat);

/* ODE message routing: handlers format into a ring buffer; Python drains it into logging. */
void odin_install_handlers(void);
/* Copies the oldest buffered message into buf (NUL-terminated); returns its level
 * (0 message, 1 debug, 2 error) or -1 when the buffer is empty. */
int odin_drain_message(char *buf, int size, int *errnum);
/* Test hook: routes a message through ODE's dMessage (non-fatal) path. */
void odin_test_message(int num, const char *msg);
#endif
