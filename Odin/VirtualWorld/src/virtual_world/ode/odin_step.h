/* Odin's per-step C code, compiled into the _odin_ode extension.
 *
 * One OdinWorld (allocated by Python with ffi.new, so Python owns its memory) gathers what the
 * hot loop needs: the ODE world, hash space and contact group, the contact settings, and arrays
 * of persistent body forces, joint forces and motor goals that Python rebuilds when they change.
 * odin_world_step() runs the whole count-loop (collide, forces, motors, step, empty contacts) in
 * C; nothing is created or destroyed in it except contact joints in the contact group.
 * The only memory this file allocates is the collision-record buffer (odin_world_free_buffers).
 */
#ifndef ODIN_STEP_H
#define ODIN_STEP_H
#include <ode/ode.h>

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

/* A motor goal: speeds of an amotor (kind 0) or lmotor (kind 1), set before every step. */
typedef struct OdinMotorGoal {
    dJointID motor;
    int kind;
    int naxes;
    double velocity[3];
} OdinMotorGoal;

/* A pair of geoms found colliding; depth is the deepest ODE contact depth seen. */
typedef struct OdinCollision {
    dGeomID g1, g2;
    double depth;
    int npoints;
    double points[ODIN_RECORD_POINTS][3];
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
    int solver;              /* 0 QuickStep, 1 dWorldStep */
    /* persistent actions (arrays owned by Python) */
    OdinBodyForce *forces; int n_forces;
    OdinJointForce *joint_forces; int n_joint_forces;
    OdinMotorGoal *motors; int n_motors;
    /* outputs */
    int last_step_contacts;
    int recording;           /* internal: record pairs during this collide pass */
    int record_overflow;     /* pairs dropped because memory ran out */
    OdinCollision *records; int n_records; int cap_records;
    int *table; int table_cap;   /* open addressing over records (contact-less dedupe) */
} OdinWorld;

/* Geom data (dGeomSetData) holds an entity tag as an integer: two geoms with the same non-zero
 * tag never collide (an entity without internal collisions). */
void odin_set_geom_tag(dGeomID g, long tag);
long odin_get_geom_tag(dGeomID g);

/* Runs `count` steps of `h` seconds. Returns 0. */
int odin_world_step(OdinWorld *w, double h, int count);
/* Contact-less policy: records the pairs touching now, without stepping (no-op otherwise). */
void odin_world_detect(OdinWorld *w);
/* Forgets the collision records (contact-less: after a read). */
void odin_world_clear_records(OdinWorld *w);
/* Frees the record buffer (close/new scene). */
void odin_world_free_buffers(OdinWorld *w);

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
