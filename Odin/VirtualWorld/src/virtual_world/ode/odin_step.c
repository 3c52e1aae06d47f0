/* Odin's per-step hot work in C (see odin_step.h): the broad phase's near-callback with contact
 * creation and pair recording, persistent forces, joint forces and motor goals, the step loop,
 * the vectorised pose read-out and ODE's message routing. */
#include "odin_step.h"

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- geom identity */

static const OdinGeomInfo *info_of(dGeomID g) { return (const OdinGeomInfo *)dGeomGetData(g); }

/* ---------------------------------------------------------------- collision records */

static size_t pair_hash(dGeomID a, dGeomID b) {
    uint64_t x = (uint64_t)(uintptr_t)a * 0x9E3779B97F4A7C15ull;
    x ^= (uint64_t)(uintptr_t)b + 0x7F4A7C15ull + (x << 6) + (x >> 2);
    x ^= x >> 29;
    return (size_t)x;
}

static int grow_records(OdinWorld *w) {
    int cap = w->cap_records ? 2 * w->cap_records : 256;
    OdinCollision *records = realloc(w->records, (size_t)cap * sizeof(OdinCollision));
    if (!records) return 0;
    w->records = records;
    w->cap_records = cap;
    int tcap = 2 * cap;
    int *table = realloc(w->table, (size_t)tcap * sizeof(int));
    if (!table) return 0;
    w->table = table;
    w->table_cap = tcap;
    memset(table, 0, (size_t)tcap * sizeof(int));
    for (int i = 0; i < w->n_records; ++i) {
        size_t h = pair_hash(records[i].g1, records[i].g2) & (size_t)(tcap - 1);
        while (table[h]) h = (h + 1) & (size_t)(tcap - 1);
        table[h] = i + 1;
    }
    return 1;
}

/* The deepest of n contacts' depths (m); 0 for none. */
static double deepest(const dContact *c, int n) {
    double depth = 0.0;
    for (int i = 0; i < n; ++i)
        if (c[i].geom.depth > depth) depth = c[i].geom.depth;
    return depth;
}

/* Records a colliding pair (o1 the lower serial), keeping its deepest occurrence; returns the
 * record's index, or -1 (memory ran out, or a shallower occurrence of a recorded pair). */
static int record_pair(OdinWorld *w, dGeomID o1, dGeomID o2, const dContact *c, int n) {
    dGeomID a = o1, b = o2;
    double depth = deepest(c, n);
    OdinCollision *r = NULL;
    if (w->table_cap) {
        size_t mask = (size_t)(w->table_cap - 1);
        size_t h = pair_hash(a, b) & mask;
        while (w->table[h]) {
            OdinCollision *q = &w->records[w->table[h] - 1];
            if (q->g1 == a && q->g2 == b) { r = q; break; }
            h = (h + 1) & mask;
        }
        if (r && depth <= r->depth) return -1; /* keep the deepest occurrence */
    }
    if (!r) {
        if (w->n_records >= w->cap_records && !grow_records(w)) { w->record_overflow++; return -1; }
        r = &w->records[w->n_records++];
        r->g1 = a;
        r->g2 = b;
        r->first_step = w->step_count;
        size_t mask = (size_t)(w->table_cap - 1);
        size_t h = pair_hash(a, b) & mask;
        while (w->table[h]) h = (h + 1) & mask;
        w->table[h] = w->n_records;
    }
    r->depth = depth;
    r->npoints = n < ODIN_RECORD_POINTS ? n : ODIN_RECORD_POINTS;
    r->has_forces = 0;
    for (int i = 0; i < r->npoints; ++i)
        for (int k = 0; k < 3; ++k) {
            r->points[i][k] = c[i].geom.pos[k];
            r->normals[i][k] = c[i].geom.normal[k];
        }
    return (int)(r - w->records);
}

void odin_world_clear_records(OdinWorld *w) {
    w->n_records = 0;
    if (w->table) memset(w->table, 0, (size_t)w->table_cap * sizeof(int));
}

void odin_world_free_buffers(OdinWorld *w) {
    free(w->records);
    free(w->table);
    free(w->diverged);
    w->diverged = NULL;
    free(w->feedback);
    free(w->feedback_record);
    free(w->feedback_point);
    free(w->feedback_sign);
    w->feedback = NULL;
    w->feedback_record = w->feedback_point = w->feedback_sign = NULL;
    w->n_feedback = w->cap_feedback = 0;
    w->n_diverged = w->cap_diverged = 0;
    free(w->island_keys);
    free(w->island_index);
    free(w->island_stack);
    w->island_keys = NULL;
    w->island_index = w->island_stack = NULL;
    w->island_cap = 0;
    free(w->pairs);
    free(w->pairs_sorted);
    free(w->contacts);
    w->records = NULL;
    w->table = NULL;
    w->pairs = w->pairs_sorted = NULL;
    w->contacts = NULL;
    w->n_records = w->cap_records = w->table_cap = 0;
    w->n_pairs = w->cap_pairs = w->n_contacts = w->cap_contacts = 0;
}

/* ---------------------------------------------------------------- a pass's pairs, in order */

/* Keeps a colliding pair's contacts until the pass ends; 0 when memory ran out. */
static int keep_pair(OdinWorld *w, dGeomID g1, dGeomID g2, long s1, long s2,
                     const dContact *c, int n, int record) {
    if (w->n_pairs >= w->cap_pairs) {
        int cap = w->cap_pairs ? 2 * w->cap_pairs : 256;
        OdinPair *pairs = realloc(w->pairs, (size_t)cap * sizeof(OdinPair));
        if (!pairs) return 0;
        w->pairs = pairs;
        OdinPair *sorted = realloc(w->pairs_sorted, (size_t)cap * sizeof(OdinPair));
        if (!sorted) return 0;
        w->pairs_sorted = sorted;
        w->cap_pairs = cap;
    }
    if (w->n_contacts + n > w->cap_contacts) {
        int cap = w->cap_contacts ? 2 * w->cap_contacts : 1024;
        while (cap < w->n_contacts + n) cap *= 2;
        dContactGeom *contacts = realloc(w->contacts, (size_t)cap * sizeof(dContactGeom));
        if (!contacts) return 0;
        w->contacts = contacts;
        w->cap_contacts = cap;
    }
    OdinPair *p = &w->pairs[w->n_pairs++];
    p->g1 = g1; p->g2 = g2;
    p->key = (uint64_t)s1 << 32 | (uint64_t)(uint32_t)s2;
    p->first = w->n_contacts;
    p->n = n;
    p->record = record;
    for (int i = 0; i < n; ++i) w->contacts[w->n_contacts++] = c[i].geom;
    return 1;
}

/* Up to this many pairs are sorted by insertion: the radix sort's eight passes over its 256
 * counters cost more than a few dozen comparisons (a planner's small scenes, every step). */
#define INSERTION_SORT_PAIRS 24

/* Sorts the pass's pairs by key (keys are unique: each pair of geoms is met once a pass): by
 * insertion when there are few, otherwise a least-significant-digit radix sort, a byte at a
 * time, skipping the bytes every key shares (with fewer than 65,536 geoms, four of the
 * eight): a few operations per pair, where qsort's comparisons cost a step 3 % of its
 * instructions. */
static void sort_pairs(OdinWorld *w) {
    int n = w->n_pairs, count[256];
    OdinPair *from = w->pairs, *to = w->pairs_sorted;
    if (n <= INSERTION_SORT_PAIRS) {
        for (int i = 1; i < n; ++i) {
            OdinPair p = from[i];
            int j = i;
            for (; j > 0 && from[j - 1].key > p.key; --j) from[j] = from[j - 1];
            from[j] = p;
        }
        return;
    }
    for (int shift = 0; shift < 64; shift += 8) {
        memset(count, 0, sizeof count);
        for (int i = 0; i < n; ++i) count[(from[i].key >> shift) & 255]++;
        if (count[(from[0].key >> shift) & 255] == n) continue; /* one byte value: in order */
        for (int b = 0, sum = 0; b < 256; ++b) { int c = count[b]; count[b] = sum; sum += c; }
        for (int i = 0; i < n; ++i) to[count[(from[i].key >> shift) & 255]++] = from[i];
        OdinPair *t = from; from = to; to = t;
    }
    w->pairs = from;
    w->pairs_sorted = to;
}

/* ---------------------------------------------------------------- surfaces */

static double min2(double a, double b) { return a < b ? a : b; }
static double max2(double a, double b) { return a > b ? a : b; }

/* Springs (and dampers) in series: 1/k = 1/k1 + 1/k2; a side without one is rigid. */
static double series(int has1, double k1, int has2, double k2) {
    if (!has1) return k2;
    if (!has2) return k1;
    return k1 + k2 > 0 ? k1 * k2 / (k1 + k2) : 0.0;
}

/* The surface of a contact between g1 and g2 (docs/INTERFACE.md, Messages/Surface): the
 * smaller friction, the larger restitution, the smaller bounce velocity, stiffness and damping
 * in series; what neither sets is the world's. fdir (world frame) is set when the contact is
 * anisotropic: the direction of the first surface that has one, along which friction2 acts
 * (the smaller of the two surfaces' frictions along it) and friction across it. h: the step
 * (s). Returns whether the contact is anisotropic. */
static int mix_surface(const OdinWorld *w, dGeomID g1, dGeomID g2, double h,
                       dSurfaceParameters *s, dVector3 fdir) {
    const OdinGeomInfo *a = info_of(g1), *b = info_of(g2);
    int mode = dContactApprox1;
    double mu_a = a->has_friction ? a->mu : w->mu, mu_b = b->has_friction ? b->mu : w->mu;
    s->mu = min2(mu_a, mu_b);
    const OdinGeomInfo *aniso = a->has_friction2 ? a : b->has_friction2 ? b : NULL;
    if (aniso) {
        dGeomID owner = aniso == a ? g1 : g2;
        const dReal *R = dGeomGetRotation(owner);
        for (int k = 0; k < 3; ++k)
            fdir[k] = R[4 * k] * aniso->fdir[0] + R[4 * k + 1] * aniso->fdir[1]
                      + R[4 * k + 2] * aniso->fdir[2];
        double mu2_a = a->has_friction2 ? a->mu2 : mu_a, mu2_b = b->has_friction2 ? b->mu2 : mu_b;
        s->mu2 = s->mu;                  /* ODE: mu acts along fdir1, mu2 across it */
        s->mu = min2(mu2_a, mu2_b);
        mode |= dContactMu2 | dContactFDir1;
    }
    if (a->has_bounce || b->has_bounce) {
        s->bounce = max2(a->has_bounce ? a->bounce : w->bounce, b->has_bounce ? b->bounce : w->bounce);
        s->bounce_vel = min2(a->has_bounce ? a->bounce_vel : w->bounce_vel,
                             b->has_bounce ? b->bounce_vel : w->bounce_vel);
    } else {
        s->bounce = w->bounce;
        s->bounce_vel = w->bounce_vel;
    }
    if (s->bounce > 0) mode |= dContactBounce;
    if (a->has_softness || b->has_softness) {
        double kp = series(a->has_softness, a->kp, b->has_softness, b->kp);
        double kd = series(a->has_softness, a->kd, b->has_softness, b->kd);
        s->soft_erp = h * kp / (h * kp + kd);
        s->soft_cfm = 1.0 / (h * kp + kd);
        mode |= dContactSoftERP | dContactSoftCFM;
    }
    s->mode = mode;
    return aniso != NULL;
}

/* Projects the friction direction f onto the contact plane of normal n (ODE wants fdir1 in
 * it); 0 when f is along n, where no direction is left. */
static int in_contact_plane(dVector3 f, const dVector3 n) {
    dReal d = f[0] * n[0] + f[1] * n[1] + f[2] * n[2];
    for (int k = 0; k < 3; ++k) f[k] -= d * n[k];
    dReal len = dSqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    if (len < 1e-9) return 0;
    for (int k = 0; k < 3; ++k) f[k] /= len;
    return 1;
}

/* Room for the joint feedback of n contacts; 0 when memory ran out (then no forces). */
static int feedback_room(OdinWorld *w, int n) {
    if (n <= w->cap_feedback) return 1;
    int cap = w->cap_feedback ? w->cap_feedback : 256;
    while (cap < n) cap *= 2;
    dJointFeedback *f = realloc(w->feedback, (size_t)cap * sizeof(dJointFeedback));
    if (f) w->feedback = f;
    int *r = realloc(w->feedback_record, (size_t)cap * sizeof(int));
    if (r) w->feedback_record = r;
    int *p = realloc(w->feedback_point, (size_t)cap * sizeof(int));
    if (p) w->feedback_point = p;
    int *g = realloc(w->feedback_sign, (size_t)cap * sizeof(int));
    if (g) w->feedback_sign = g;
    if (!f || !r || !p || !g) return 0;
    w->cap_feedback = cap;
    return 1;
}

/* After the step: each recorded contact's force on the pair's first geom, from ODE's joint
 * feedback (f1 is the force on the joint's first body: the first geom's, or, when that geom is
 * static, the other's, whose opposite it then is). */
static void read_contact_forces(OdinWorld *w) {
    for (int k = 0; k < w->n_feedback; ++k) {
        OdinCollision *r = &w->records[w->feedback_record[k]];
        int i = w->feedback_point[k];
        for (int j = 0; j < 3; ++j) r->forces[i][j] = w->feedback_sign[k] * w->feedback[k].f1[j];
        r->has_forces = 1;
    }
    w->n_feedback = 0;
}

/* Creates the pass's contact joints, pair by pair in serial order: the same scene gives the
 * same constraints in the same order, whatever order the broad phase found the pairs in. While
 * recording, the contacts of recorded pairs get joint feedback (read_contact_forces). */
static void make_contacts(OdinWorld *w, double h) {
    if (!w->unordered && w->n_pairs > 1) sort_pairs(w);
    int feedback = w->recording && !w->pairs_only && feedback_room(w, w->n_contacts);
    w->n_feedback = 0;
    for (int k = 0; k < w->n_pairs; ++k) {
        const OdinPair *p = &w->pairs[k];
        dBodyID b1 = dGeomGetBody(p->g1), b2 = dGeomGetBody(p->g2);
        dContact contact;
        memset(&contact, 0, sizeof contact);
        int anisotropic = mix_surface(w, p->g1, p->g2, h, &contact.surface, contact.fdir1);
        for (int i = 0; i < p->n; ++i) {
            dContact c = contact;
            c.geom = w->contacts[p->first + i];
            if (anisotropic && !in_contact_plane(c.fdir1, c.geom.normal))
                c.surface.mode &= ~(dContactMu2 | dContactFDir1); /* along the normal */
            dJointID joint = dJointCreateContact(w->world, w->contact_group, &c);
            dJointAttach(joint, b1, b2);
            if (feedback && p->record >= 0 && i < ODIN_RECORD_POINTS) {
                int k = w->n_feedback++;
                dJointSetFeedback(joint, &w->feedback[k]);
                w->feedback_record[k] = p->record;
                w->feedback_point[k] = i;
                w->feedback_sign[k] = b1 ? 1 : -1;
            }
        }
        w->last_step_contacts += p->n;
    }
    w->n_pairs = w->n_contacts = 0;
}

/* ---------------------------------------------------------------- exempt pairs */

/* The index of the live exempt pair with this key, or -1 (a binary search: keys ascend). */
static int live_exempt(const OdinWorld *w, uint64_t key) {
    int lo = 0, hi = w->n_exempt - 1;
    while (lo <= hi) {
        int mid = lo + (hi - lo) / 2;
        uint64_t k = w->exempt_keys[mid];
        if (k == key) return w->exempt_live[mid] != 0.0 ? mid : -1;
        if (k < key) lo = mid + 1;
        else hi = mid - 1;
    }
    return -1;
}

/* A live exempt pair met by the broad phase. Deeper than its limit in a step's pass: it parts
 * now and 0 is returned (the caller collides it as any pair). Otherwise 1: recorded like any
 * colliding pair, no contacts, and marked as still inside each other while deeper than
 * exempt_depth. */
static int collide_exempt(OdinWorld *w, dGeomID o1, dGeomID o2, int e) {
    dContact contact[ODIN_MAX_CONTACTS];
    int n = dCollide(o1, o2, w->max_contacts, &contact[0].geom, sizeof(dContact));
    double depth = deepest(contact, n);
    if (depth > w->exempt_limit[e] && w->stepping) {
        w->exempt_live[e] = 0.0;
        return 0;
    }
    if (n > 0 && w->recording) record_pair(w, o1, o2, contact, n);
    if (depth > w->exempt_depth) w->exempt_seen[e] = 1;
    return 1;
}

/* After a step's collide pass: the live pairs it did not find deeper than exempt_depth have
 * parted, for good. */
static void part_exempt_pairs(OdinWorld *w) {
    for (int i = 0; i < w->n_exempt; ++i)
        if (!w->exempt_seen[i]) w->exempt_live[i] = 0.0;
}

/* ---------------------------------------------------------------- near-callback */

int odin_pair_never_touches(dGeomID o1, dGeomID o2) {
    const OdinGeomInfo *i1 = info_of(o1), *i2 = info_of(o2);
    if (i1->tag && i1->tag == i2->tag) return 1; /* same entity, no internal collisions */
    dBodyID b1 = dGeomGetBody(o1), b2 = dGeomGetBody(o2);
    if (b1 == b2) return 1; /* parts of one composite, or two static geoms */
    return b1 && b2 && dAreConnectedExcluding(b1, b2, dJointTypeContact);
}

/* A kinematic body that moves (a link under the kinematic drive, a body given a velocity); a
 * fixed body is kinematic too, but still. */
static int moving_kinematic(dBodyID b) {
    if (!b || !dBodyIsKinematic(b)) return 0;
    const dReal *v = dBodyGetLinearVel(b), *a = dBodyGetAngularVel(b);
    return v[0] != 0 || v[1] != 0 || v[2] != 0 || a[0] != 0 || a[1] != 0 || a[2] != 0;
}

static void near_callback(void *data, dGeomID o1, dGeomID o2) {
    OdinWorld *w = (OdinWorld *)data;
    if (odin_pair_never_touches(o1, o2)) return;
    const OdinGeomInfo *i1 = info_of(o1), *i2 = info_of(o2);
    if (i1->serial > i2->serial) { /* collide in serial order: the same contacts every time */
        dGeomID g = o1; o1 = o2; o2 = g;
        const OdinGeomInfo *i = i1; i1 = i2; i2 = i;
    }
    dBodyID b1 = dGeomGetBody(o1), b2 = dGeomGetBody(o2);
    if (w->n_exempt) {
        int e = live_exempt(w, (uint64_t)i1->serial << 32 | (uint64_t)(uint32_t)i2->serial);
        if (e >= 0 && collide_exempt(w, o1, o2, e)) return;
    }
    if (!w->contact_less) {
        int dynamic = (b1 && !dBodyIsKinematic(b1)) || (b2 && !dBodyIsKinematic(b2));
        /* nothing the solver can move: no contact needed; but a moving kinematic body (two
         * arms under the kinematic drive, one driven through a wall) still meets what it
         * passes through, and a recording pass must say so */
        if (!dynamic && !(w->recording && (moving_kinematic(b1) || moving_kinematic(b2))))
            return;
        if (!dynamic) {
            dContact met[ODIN_MAX_CONTACTS];
            int n = dCollide(o1, o2, w->max_contacts, &met[0].geom, sizeof(dContact));
            if (n > 0) record_pair(w, o1, o2, met, n);
            return;
        }
    }
    dContact contact[ODIN_MAX_CONTACTS];
    int n = dCollide(o1, o2, w->max_contacts, &contact[0].geom, sizeof(dContact));
    if (n <= 0) return;
    int record = w->recording ? record_pair(w, o1, o2, contact, n) : -1;
    if (w->contact_less) return;
    if (!keep_pair(w, o1, o2, i1->serial, i2->serial, contact, n, record))
        w->buffer_overflow++;
}

/* ---------------------------------------------------------------- persistent actions */

static void apply_body_force(const OdinBodyForce *f) {
    const double *v = f->vector, *p = f->point;
    if (f->torque) {
        if (f->vector_in_body) dBodyAddRelTorque(f->body, v[0], v[1], v[2]);
        else dBodyAddTorque(f->body, v[0], v[1], v[2]);
    } else if (!f->at_point) {
        if (f->vector_in_body) dBodyAddRelForce(f->body, v[0], v[1], v[2]);
        else dBodyAddForce(f->body, v[0], v[1], v[2]);
    } else if (f->vector_in_body) {
        if (f->point_in_body) dBodyAddRelForceAtRelPos(f->body, v[0], v[1], v[2], p[0], p[1], p[2]);
        else dBodyAddRelForceAtPos(f->body, v[0], v[1], v[2], p[0], p[1], p[2]);
    } else {
        if (f->point_in_body) dBodyAddForceAtRelPos(f->body, v[0], v[1], v[2], p[0], p[1], p[2]);
        else dBodyAddForceAtPos(f->body, v[0], v[1], v[2], p[0], p[1], p[2]);
    }
}

/* The persistent forces, then a propagation's own (odin_world_propagate): a propagation's
 * force comes last, as it did when it was added to the persistent ones for the call, so that
 * ODE sums a body's forces in the same order either way. */
static void apply_body_forces(const OdinWorld *w) {
    for (int i = 0; i < w->n_forces; ++i) apply_body_force(&w->forces[i]);
    for (int i = 0; i < w->n_propagation_forces; ++i)
        apply_body_force(&w->propagation_forces[i]);
}

/* Adds +v to the first body and -v to the second, as torque or force (ODE's own convention). */
static void add_pair(dJointID j, const dReal *v, int torque) {
    dBodyID b1 = dJointGetBody(j, 0), b2 = dJointGetBody(j, 1);
    if (torque) {
        if (b1) dBodyAddTorque(b1, v[0], v[1], v[2]);
        if (b2) dBodyAddTorque(b2, -v[0], -v[1], -v[2]);
    } else {
        if (b1) dBodyAddForce(b1, v[0], v[1], v[2]);
        if (b2) dBodyAddForce(b2, -v[0], -v[1], -v[2]);
    }
}

static void apply_joint_forces(const OdinWorld *w) {
    for (int i = 0; i < w->n_joint_forces; ++i) {
        const OdinJointForce *f = &w->joint_forces[i];
        const double *m = f->magnitude;
        dVector3 a1, a2, v;
        switch (f->type) {
        case dJointTypeBall:
            v[0] = m[0]; v[1] = m[1]; v[2] = m[2];
            add_pair(f->joint, v, 1);
            break;
        case dJointTypeHinge: dJointAddHingeTorque(f->joint, m[0]); break;
        case dJointTypeSlider: dJointAddSliderForce(f->joint, m[0]); break;
        case dJointTypePiston: dJointAddPistonForce(f->joint, m[0]); break;
        case dJointTypeUniversal: dJointAddUniversalTorques(f->joint, m[0], m[1]); break;
        case dJointTypeHinge2: dJointAddHinge2Torques(f->joint, m[0], m[1]); break;
        case dJointTypePR:
            dJointGetPRAxis1(f->joint, a1);
            for (int k = 0; k < 3; ++k) v[k] = a1[k] * m[0];
            add_pair(f->joint, v, 0);
            dJointAddPRTorque(f->joint, m[1]);
            break;
        case dJointTypePU: /* libode 0.16 declares dJointAddPUTorque but does not export it */
            dJointGetPUAxis1(f->joint, a1);
            dJointGetPUAxis2(f->joint, a2);
            for (int k = 0; k < 3; ++k) v[k] = a1[k] * m[0] + a2[k] * m[1];
            add_pair(f->joint, v, 1);
            break;
        default: break; /* Python never queues other types */
        }
    }
}

/* A joint's value (rad or m): component c of what JointState reports for its type. */
static double joint_value(dJointID j, int type, int c) {
    switch (type) {
    case dJointTypeHinge: return dJointGetHingeAngle(j);
    case dJointTypeSlider: return dJointGetSliderPosition(j);
    case dJointTypePiston: return c == 0 ? dJointGetPistonPosition(j) : dJointGetPistonAngle(j);
    case dJointTypeUniversal: return c == 0 ? dJointGetUniversalAngle1(j) : dJointGetUniversalAngle2(j);
    case dJointTypeHinge2: return c == 0 ? dJointGetHinge2Angle1(j) : dJointGetHinge2Angle2(j);
    case dJointTypePR: return c == 0 ? dJointGetPRPosition(j) : dJointGetPRAngle(j);
    case dJointTypePU:
        return c == 0 ? dJointGetPUPosition(j) : c == 1 ? dJointGetPUAngle1(j) : dJointGetPUAngle2(j);
    default: return 0.0; /* Python never puts a servo on other types */
    }
}

/* Whether a hinge can turn past +-pi: ODE reads its angle in [-pi, pi] and honours only stops
 * inside that range, so one without both such stops (gui.core.translate.joints sets none for a
 * joint whose range passes +-pi) has angles the reading cannot tell apart. */
static int hinge_turns(dJointID j) {
    double low = dJointGetHingeParam(j, dParamLoStop), high = dJointGetHingeParam(j, dParamHiStop);
    return !(low >= -M_PI - 1e-9 && high <= M_PI + 1e-9);
}

/* The angle one whole turn or more from `angle` nearest `reference` (rad). */
static double nearest_turn(double angle, double reference) {
    return angle + 2.0 * M_PI * nearbyint((reference - angle) / (2.0 * M_PI));
}

static void apply_motor_goals(OdinWorld *w) {
    for (int i = 0; i < w->n_motors; ++i) {
        OdinMotorGoal *g = &w->motors[i];
        int turns = g->servo && g->joint_type == dJointTypeHinge && hinge_turns(g->joint);
        for (int k = 0; k < g->naxes; ++k) {
            double v = g->velocity[k];
            if (g->servo) {
                double q = g->sign[k] * joint_value(g->joint, g->joint_type, g->component[k]);
                if (turns) q = nearest_turn(q, g->read ? g->position[k] : g->target[k]);
                g->position[k] = q;
                v = g->target_rate[k] + g->gain[k] * (g->target[k] - q);
                if (v > g->max_speed[k]) v = g->max_speed[k];
                if (v < -g->max_speed[k]) v = -g->max_speed[k];
            }
            g->speed[k] = v;
            if (g->kind == 0) dJointSetAMotorParam(g->motor, dParamVel + k * dParamGroup, v);
            else dJointSetLMotorParam(g->motor, dParamVel + k * dParamGroup, v);
        }
        if (g->servo) g->read = 1;
    }
}

/* ---------------------------------------------------------------- the divergence guard */

static double clamp_to(double x, double bound) {
    if (!isfinite(x)) return 0.0;
    return x > bound ? bound : x < -bound ? -bound : x;
}

/* Parks a body that went wrong: still, kinematic, colliding with nothing, within the extent,
 * its rotation finite; then no later collide or step can meet its values. */
static void park(const OdinWorld *w, dBodyID b) {
    const dReal *p = dBodyGetPosition(b), *q = dBodyGetQuaternion(b);
    double x = clamp_to(p[0], w->extent), y = clamp_to(p[1], w->extent),
           z = clamp_to(p[2], w->extent);
    if (!(isfinite(q[0]) && isfinite(q[1]) && isfinite(q[2]) && isfinite(q[3]))) {
        dQuaternion identity = {1, 0, 0, 0};
        dBodySetQuaternion(b, identity);
    }
    dBodySetPosition(b, x, y, z);
    dBodySetLinearVel(b, 0, 0, 0);
    dBodySetAngularVel(b, 0, 0, 0);
    dBodySetForce(b, 0, 0, 0);
    dBodySetTorque(b, 0, 0, 0);
    dBodySetKinematic(b);
    for (dGeomID g = dBodyGetFirstGeom(b); g; g = dBodyGetNextGeom(g)) {
        dGeomSetCategoryBits(g, 0);
        dGeomSetCollideBits(g, 0);
    }
}

static int finite3(const dReal *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }
static double norm3(const dReal *v) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/* Why a body broke the guard's bounds (0: it did not), and by how much. */
static int diverged(const OdinWorld *w, dBodyID b, double *value) {
    const dReal *p = dBodyGetPosition(b), *q = dBodyGetQuaternion(b);
    const dReal *v = dBodyGetLinearVel(b), *a = dBodyGetAngularVel(b);
    if (!finite3(p) || !finite3(v) || !finite3(a) || !isfinite(q[0]) || !isfinite(q[1])
        || !isfinite(q[2]) || !isfinite(q[3])) {
        *value = NAN;
        return 1;
    }
    if ((*value = norm3(v)) > w->max_speed) return 2;
    if ((*value = norm3(a)) > w->max_spin) return 3;
    for (int k = 0; k < 3; ++k)
        if (fabs(*value = p[k]) > w->extent) return 4;
    return 0;
}

/* Checks every guarded body after a step; parks and records those gone wrong (and drops them
 * from the guarded list). Returns how many it parked. */
static int guard(OdinWorld *w) {
    int parked = 0;
    for (int i = 0; i < w->n_guarded; ++i) {
        dBodyID b = w->guarded[i];
        double value;
        int reason = diverged(w, b, &value);
        if (!reason) continue;
        if (w->n_diverged >= w->cap_diverged) {
            int cap = w->cap_diverged ? 2 * w->cap_diverged : 16;
            OdinDivergence *more = realloc(w->diverged, (size_t)cap * sizeof(OdinDivergence));
            if (more) { w->diverged = more; w->cap_diverged = cap; }
        }
        if (w->n_diverged < w->cap_diverged) {
            OdinDivergence *d = &w->diverged[w->n_diverged++];
            d->body = b;
            d->reason = reason;
            d->value = value;
            memcpy(d->position, dBodyGetPosition(b), sizeof d->position);
            memcpy(d->velocity, dBodyGetLinearVel(b), sizeof d->velocity);
            memcpy(d->angular, dBodyGetAngularVel(b), sizeof d->angular);
            d->step = w->step_count;
        }
        park(w, b);
        w->guarded[i--] = w->guarded[--w->n_guarded]; /* no longer guarded */
        parked++;
    }
    return parked;
}

void odin_world_clear_divergences(OdinWorld *w) { w->n_diverged = 0; }

/* ---------------------------------------------------------------- sleeping bodies */

void odin_world_sync_auto_disable(OdinWorld *w) {
    dWorldSetAutoDisableFlag(w->world, w->auto_disable);
    for (int i = 0; i < w->n_guarded; ++i) dBodySetAutoDisableFlag(w->guarded[i], w->auto_disable);
}

void odin_world_wake(OdinWorld *w) {
    for (int i = 0; i < w->n_guarded; ++i) dBodyEnable(w->guarded[i]);
}

/* dBodyEnable is ODE's only way to set a body's rest count (to its idle steps). */
static void restart_rest_count(dBodyID b) {
    int asleep = !dBodyIsEnabled(b);
    dBodyEnable(b);
    if (asleep) dBodyDisable(b);
}

void odin_world_restart_rest_counts(OdinWorld *w) {
    for (int i = 0; i < w->n_guarded; ++i) restart_rest_count(w->guarded[i]);
}

int odin_world_sleeping(const OdinWorld *w) {
    int n = 0;
    for (int i = 0; i < w->n_guarded; ++i) n += !dBodyIsEnabled(w->guarded[i]);
    return n;
}

/* ODE steps only awake bodies and clears only their accumulators: the persistent forces added
 * to a sleeping body every step would pile up and all act on it the step it wakes. */
static void clear_sleepers_forces(const OdinWorld *w) {
    for (int i = 0; i < w->n_guarded; ++i) {
        dBodyID b = w->guarded[i];
        if (dBodyIsEnabled(b)) continue;
        dBodySetForce(b, 0, 0, 0);
        dBodySetTorque(b, 0, 0, 0);
    }
}

/* ---------------------------------------------------------------- step (thesis 5.5) */

/* ---------------------------------------------------------------- the auto solver's measure */

/* ODE's testRotationalLimit: a limit [lo, hi] (lo <= hi) is active at `value` on or past it. */
static int limit_active(double lo, double hi, double value) {
    return lo <= hi && (value <= lo || value >= hi);
}

/* 1 when axis `axis` (0..2) of a motor or of a joint's own motor/limit adds a row: powered
 * (FMax > 0) or at an active limit. */
static int axis_row(dReal (*get)(dJointID, int), dJointID j, int axis, double value) {
    int g = dParamGroup * axis;
    return get(j, dParamFMax + g) > 0 ||
           limit_active(get(j, dParamLoStop + g), get(j, dParamHiStop + g), value);
}

/* The rows a joint adds to ODE's constraint system this step (its getInfo1's m, ODE 0.16):
 * the fixed rows of its type, plus one per axis that is powered or at an active limit. A
 * contact is counted at 3 (friction on; its surface is not readable through ODE's API). */
static int joint_rows(dJointID j) {
    int m = 0;
    switch (dJointGetType(j)) {
    case dJointTypeContact: case dJointTypeBall:
        return 3;
    case dJointTypeFixed:
        return 6;
    case dJointTypeDBall: case dJointTypeTransmission:
        return 1;
    case dJointTypeHinge:
        return 5 + axis_row(dJointGetHingeParam, j, 0, dJointGetHingeAngle(j));
    case dJointTypeSlider:
        return 5 + axis_row(dJointGetSliderParam, j, 0, dJointGetSliderPosition(j));
    case dJointTypeUniversal:
        return 4 + axis_row(dJointGetUniversalParam, j, 0, dJointGetUniversalAngle1(j))
                 + axis_row(dJointGetUniversalParam, j, 1, dJointGetUniversalAngle2(j));
    case dJointTypeHinge2:
        return 4 + axis_row(dJointGetHinge2Param, j, 0, dJointGetHinge2Angle1(j))
                 + (dJointGetHinge2Param(j, dParamFMax2) > 0);
    case dJointTypeAMotor:
        for (int i = 0; i < dJointGetAMotorNumAxes(j); ++i)
            m += axis_row(dJointGetAMotorParam, j, i, dJointGetAMotorAngle(j, i));
        return m;
    case dJointTypeLMotor:
        for (int i = 0; i < dJointGetLMotorNumAxes(j); ++i)
            m += dJointGetLMotorParam(j, dParamFMax + dParamGroup * i) > 0;
        return m;
    default:                  /* PR, PU, piston, plane-2D, double hinge: their most */
        return 6;
    }
}

/* The rows a joint adds at most (its getInfo1's m with every limit and motor active): the
 * small-system clause's measure, kept as it was when the pinned planning experiments were
 * recorded (their plans replay only if auto chooses the same solver at every step). */
static int joint_rows_at_most(dJointID j) {
    switch (dJointGetType(j)) {
    case dJointTypeContact: case dJointTypeBall: case dJointTypePlane2D:
    case dJointTypeAMotor: case dJointTypeLMotor:
        return 3;
    case dJointTypeDBall: case dJointTypeTransmission:
        return 1;
    default:                  /* hinge, slider, universal, hinge-2, fixed, PR, PU, piston... */
        return 6;
    }
}

/* The whole step's rows by joint_rows_at_most, counting stops above `bound`. Each joint is
 * counted at its first dynamic body (a parked body is kinematic, hence fixed); a sleeping
 * body's joints are not stepped. */
static int step_rows_at_most(const OdinWorld *w, int bound) {
    int rows = 0;
    for (int i = 0; i < w->n_guarded; ++i) {
        dBodyID b = w->guarded[i];
        if (!dBodyIsEnabled(b)) continue;
        int n = dBodyGetNumJoints(b);
        for (int k = 0; k < n; ++k) {
            dJointID j = dBodyGetJoint(b, k);
            dBodyID first = dJointGetBody(j, 0);
            if (!first || dBodyIsKinematic(first)) first = dJointGetBody(j, 1);
            if (first != b || !dJointIsEnabled(j)) continue;
            if ((rows += joint_rows_at_most(j)) > bound) return rows;
        }
    }
    return rows;
}

static int dynamic(dBodyID b) { return b && !dBodyIsKinematic(b); }

/* The guarded body's index, or -1 (a hash of the guarded bodies' addresses, built per step). */
static int guarded_index(const OdinWorld *w, dBodyID b) {
    size_t mask = (size_t)(w->island_cap - 1);
    for (size_t h = pair_hash(b, b) & mask; w->island_keys[h]; h = (h + 1) & mask)
        if (w->island_keys[h] == b) return w->island_index[h];
    return -1;
}

/* 1 when an awake dynamic body has an enabled joint other than a contact: without one every
 * island is contacts only (a pile, bodies at rest) and auto takes QuickStep without searching
 * the islands (a walk over the bodies' joints, no hash: cheap on 10,000 bodies at rest). */
static int articulated(const OdinWorld *w) {
    for (int i = 0; i < w->n_guarded; ++i) {
        dBodyID b = w->guarded[i];
        if (!dBodyIsEnabled(b) || dBodyIsKinematic(b)) continue;
        int nj = dBodyGetNumJoints(b);
        for (int k = 0; k < nj; ++k) {
            dJointID j = dBodyGetJoint(b, k);
            if (dJointGetType(j) != dJointTypeContact && dJointIsEnabled(j)) return 1;
        }
    }
    return 0;
}

/* Finds ODE's islands this step (the awake dynamic bodies joined by enabled joints; static
 * and kinematic bodies join nothing, as in ODE's dxProcessIslands) and sets island_rows (the
 * largest island's rows) and articulated_rows (the most rows of non-contact joints, motors and
 * limits included, in one island); both 0 when nothing is articulated. Each joint is counted
 * once, at its first dynamic body. `most`: the most rows of non-contact joints in one island
 * counted as the small-system clause counts them (joint_rows_at_most). 0 when memory ran out
 * (auto then takes QuickStep). */
static int measure_islands(OdinWorld *w, int *most) {
    int n = w->n_guarded;
    w->island_rows = w->articulated_rows = 0;
    *most = 0;
    if (!articulated(w)) return 1;
    if (w->island_cap < 2 * n) {
        int cap = 16;
        while (cap < 2 * n) cap *= 2;
        dBodyID *keys = realloc(w->island_keys, (size_t)cap * sizeof(dBodyID));
        if (keys) w->island_keys = keys;
        int *index = realloc(w->island_index, (size_t)cap * sizeof(int));
        if (index) w->island_index = index;
        int *stack = realloc(w->island_stack, (size_t)cap * sizeof(int));
        if (stack) w->island_stack = stack;
        if (!keys || !index || !stack) return 0;
        w->island_cap = cap;
    }
    size_t mask = (size_t)(w->island_cap - 1);
    memset(w->island_keys, 0, (size_t)w->island_cap * sizeof(dBodyID));
    for (int i = 0; i < n; ++i) {
        size_t h = pair_hash(w->guarded[i], w->guarded[i]) & mask;
        while (w->island_keys[h]) h = (h + 1) & mask;
        w->island_keys[h] = w->guarded[i];
        w->island_index[h] = i;
    }
    /* island_stack's upper half marks the bodies already in an island */
    int *seen = w->island_stack + w->island_cap / 2;
    memset(seen, 0, (size_t)n * sizeof(int));
    for (int i = 0; i < n; ++i) {
        dBodyID start = w->guarded[i];
        if (seen[i] || !dBodyIsEnabled(start) || dBodyIsKinematic(start)) continue;
        int top = 0, rows = 0, articulated = 0, articulated_most = 0;
        seen[i] = 1;
        w->island_stack[top++] = i;
        while (top) {
            dBodyID b = w->guarded[w->island_stack[--top]];
            int nj = dBodyGetNumJoints(b);
            for (int k = 0; k < nj; ++k) {
                dJointID j = dBodyGetJoint(b, k);
                if (!dJointIsEnabled(j)) continue;
                dBodyID first = dJointGetBody(j, 0), second = dJointGetBody(j, 1);
                if (!dynamic(first)) first = second;
                if (first == b) {
                    int r = joint_rows(j);
                    rows += r;
                    if (dJointGetType(j) != dJointTypeContact) {
                        articulated += r;
                        articulated_most += joint_rows_at_most(j);
                    }
                }
                dBodyID other = dJointGetBody(j, 0) == b ? second : dJointGetBody(j, 0);
                if (!dynamic(other)) continue;
                int o = guarded_index(w, other);
                if (o < 0 || seen[o]) continue;
                seen[o] = 1;
                w->island_stack[top++] = o;
            }
        }
        if (rows > w->island_rows) w->island_rows = rows;
        if (articulated > w->articulated_rows) w->articulated_rows = articulated;
        if (articulated_most > *most) *most = articulated_most;
    }
    return 1;
}

/* 0 QuickStep or 1 dWorldStep for this step. Auto takes the exact solver when either
 * clause holds:
 *  - a small system: the whole step has at most auto_step_rows rows by joint_rows_at_most
 *    (a few bodies, a short arm, a car on the ground: exact and faster than QuickStep's
 *    iterations; the pinned planning experiments were recorded under this clause alone);
 *  - a large articulation: an island whose joints and motors alone (contacts aside), counted
 *    as the first clause counts them (joint_rows_at_most), have at least
 *    auto_articulation_rows rows: five servo-held joints or more, a manipulator arm with or
 *    without its gripper or hand (the TX90 with its hand: 24 joints, 216 rows so counted; a 12-hinge arm
 *    and gripper, 150, whose 114 rows by ODE's count left it to QuickStep when the clause
 *    counted ODE's rows; a YuMi arm on its kinematic base, 9 joints), while the largest
 *    island has at most auto_rows rows by ODE's count. QuickStep's iterations let such a chain held by
 *    its motors fold or shake; ODE steps each island on its own and dWorldStep's cost is
 *    cubic in an island's rows, so the largest island bounds its cost (the TX90 + hand
 *    grasping a can: about 300).
 * Anything else (piles, many bodies at rest, a small robot among many contacts, a larger
 * island) takes QuickStep, linear in the rows, as it did before the second clause existed.
 * docs/PERFORMANCE.md has the measurements behind both bounds. The choice depends on the
 * state only: deterministic. */
static int step_solver(OdinWorld *w) {
    if (w->solver != 2) return w->solver;
    w->island_rows = w->articulated_rows = 0;
    if (step_rows_at_most(w, w->auto_step_rows) <= w->auto_step_rows) return 1;
    int articulated_most;
    if (!measure_islands(w, &articulated_most)) return 0;
    return articulated_most >= w->auto_articulation_rows && w->island_rows <= w->auto_rows;
}

int odin_world_step(OdinWorld *w, double h, int count) {
    int s;
    for (s = 0; s < count; ++s) {
        w->last_step_contacts = 0;
        /* contact policy: the pairs of the last step; contact-less: every step, kept until read */
        if (w->contact_less || w->record_every_step) {
            w->recording = 1;
        } else {
            w->recording = (s == count - 1);
            if (w->recording) odin_world_clear_records(w);
        }
        if (w->n_exempt) memset(w->exempt_seen, 0, (size_t)w->n_exempt);
        w->stepping = 1;
        dSpaceCollide(w->space, w, &near_callback);   /* 1. collisions, */
        w->stepping = 0;
        if (w->n_exempt) part_exempt_pairs(w);        /*    exempt pairs apart now part */
        if (!w->contact_less) make_contacts(w, h);    /*    contacts in serial order */
        apply_body_forces(w);                         /* 2. forces and torques on bodies */
        apply_joint_forces(w);                        /* 3. joint forces and motor goals */
        apply_motor_goals(w);
        odin_kinematic_drive(w, h);                   /*    kinematic links' velocities */
        w->last_solver = step_solver(w);
        if (w->last_solver == 0) {                    /* 4. step */
            dRandSetSeed(w->rand_seed);
            dWorldQuickStep(w->world, h);
            w->rand_seed = dRandGetSeed();
        } else {
            dWorldStep(w->world, h);
        }
        /* 5. fixed bodies are kinematic (dBodySetKinematic): nothing to reset */
        if (w->auto_disable) clear_sleepers_forces(w);
        if (w->recording && !w->contact_less) read_contact_forces(w);
        dJointGroupEmpty(w->contact_group);           /* 6. contacts last one step */
        w->step_count++;
        if (guard(w) && w->stop_on_divergence) {      /* 7. nothing diverged may go on */
            s++;
            break;
        }
    }
    w->recording = 0;
    return s;
}

/* One propagation from a body state vector (see odin_step.h), as Core.propagate runs one from
 * a start state and keeps it: the state put back, the records forgotten, the generator's state
 * set, then the step loop recording every step, then the state read. */
int odin_world_propagate(OdinWorld *w, dBodyID *bodies, int n, const double *state_in,
                         const OdinBodyForce *forces, int n_forces, double h, int count,
                         double *state_out, uintptr_t *pairs, int max_pairs, int *n_pairs) {
    *n_pairs = 0;
    int taken = odin_world_propagate_records(w, bodies, n, state_in, forces, n_forces, h, count,
                                             state_out);
    if (taken < 0) return taken;
    *n_pairs = odin_world_record_pairs(w, pairs, max_pairs);
    if (*n_pairs <= max_pairs) odin_world_clear_records(w);
    return taken;
}

int odin_world_propagate_records(OdinWorld *w, dBodyID *bodies, int n, const double *state_in,
                                 const OdinBodyForce *forces, int n_forces, double h, int count,
                                 double *state_out) {
    int size = 1 + n * ODIN_BODY_STATE_SIZE;
    int fault = odin_state_vector_fault(state_in, size + w->n_exempt, w->n_exempt);
    if (fault >= 0) return -1 - fault;
    odin_write_body_states(bodies, n, state_in + 1);
    if (w->n_exempt)
        memcpy(w->exempt_live, state_in + size, (size_t)w->n_exempt * sizeof(double));
    odin_world_clear_records(w);
    w->rand_seed = (unsigned long)state_in[0];
    w->propagation_forces = forces;
    w->n_propagation_forces = n_forces;
    w->record_every_step = w->pairs_only = 1;
    int taken = odin_world_step(w, h, count);
    w->record_every_step = w->pairs_only = 0;
    w->propagation_forces = NULL;
    w->n_propagation_forces = 0;
    state_out[0] = (double)w->rand_seed;
    odin_read_body_states(bodies, n, state_out + 1);
    if (w->n_exempt)
        memcpy(state_out + size, w->exempt_live, (size_t)w->n_exempt * sizeof(double));
    return taken;
}

/* The recorded pairs' geoms, two addresses per record, into out (room for 2 * max); returns the
 * records there are (those beyond max not written). */
int odin_world_record_pairs(const OdinWorld *w, uintptr_t *out, int max) {
    for (int i = 0; i < w->n_records && i < max; ++i) {
        out[2 * i] = (uintptr_t)w->records[i].g1;
        out[2 * i + 1] = (uintptr_t)w->records[i].g2;
    }
    return w->n_records;
}

/* Collision detection on the present poses, no step. The pairs go into the records like a
 * step's: under the contact-less policy a paused world whose objects were moved still reports
 * what touches; under the contact policy only a query asks (any_policy), and is answered as the
 * contact-less policy would, without a contact joint. */
void odin_world_detect(OdinWorld *w, int any_policy) {
    if (!w->contact_less && !any_policy) return;
    int policy = w->contact_less;
    w->contact_less = 1;
    w->recording = 1;
    dSpaceCollide(w->space, w, &near_callback);
    w->recording = 0;
    w->contact_less = policy;
}

/* ---------------------------------------------------------------- read-out */

/* A plane has no pose in ODE (it is not placeable: asking for one ends the process): it is
 * reported at its point nearest the origin, turned so that z is its normal. */
static void plane_pose(dGeomID g, double *p, double *q) {
    dVector4 abcd;
    dGeomPlaneGetParams(g, abcd);
    for (int k = 0; k < 3; ++k) p[k] = abcd[3] * abcd[k];
    /* the shortest rotation from z to the normal n: q = (1 + z.n, z x n), normalised */
    double w = 1.0 + abcd[2], x = -abcd[1], y = abcd[0], z = 0.0;
    if (w < 1e-9) { w = 0.0; x = 1.0; y = 0.0; } /* n = -z: half a turn about x */
    double len = sqrt(w * w + x * x + y * y + z * z);
    q[0] = w / len; q[1] = x / len; q[2] = y / len; q[3] = z / len;
}

void odin_read_poses(dGeomID *geoms, int n, double *pos, double *quat) {
    for (int i = 0; i < n; ++i) {
        if (dGeomGetClass(geoms[i]) == dPlaneClass) {
            plane_pose(geoms[i], pos + 3 * i, quat + 4 * i);
            continue;
        }
        const dReal *p = dGeomGetPosition(geoms[i]);
        dQuaternion q;
        dGeomGetQuaternion(geoms[i], q);
        pos[3 * i] = p[0]; pos[3 * i + 1] = p[1]; pos[3 * i + 2] = p[2];
        quat[4 * i] = q[0]; quat[4 * i + 1] = q[1]; quat[4 * i + 2] = q[2]; quat[4 * i + 3] = q[3];
    }
}

/* ---------------------------------------------------------------- ODE messages */

#define RING 64
#define TEXT 512
static struct { int level, num; char text[TEXT]; } ring[RING];
static int ring_head, ring_count;

static void push(int level, int num, const char *msg, va_list ap) {
    int slot = (ring_head + ring_count) % RING;
    if (ring_count == RING) ring_head = (ring_head + 1) % RING; /* drop the oldest */
    else ring_count++;
    ring[slot].level = level;
    ring[slot].num = num;
    vsnprintf(ring[slot].text, TEXT, msg, ap);
}

/* dError and dDebug end the process after their handler returns (exit(1) / abort()), and
 * unwinding out of ODE with longjmp would leave its state corrupt. So their handlers record the
 * message and print it to stderr at once (report_fatal), where it survives the process's end;
 * Odin validates every argument before calling ODE so that they never fire. dMessage is
 * non-fatal: buffered only, and Python drains the buffer into `logging` after each call. */
static void report_fatal(int level, const char *label, int num, const char *msg, va_list ap) {
    va_list copy;
    va_copy(copy, ap);
    push(level, num, msg, ap);
    fprintf(stderr, "%s %d: ", label, num);
    vfprintf(stderr, msg, copy);
    fputc('\n', stderr);
    fflush(stderr);
    va_end(copy);
}

static void on_error(int num, const char *msg, va_list ap) {
    report_fatal(2, "ODE error", num, msg, ap);
}

static void on_debug(int num, const char *msg, va_list ap) {
    report_fatal(1, "ODE internal error", num, msg, ap);
}

static void on_message(int num, const char *msg, va_list ap) { push(0, num, msg, ap); }

void odin_install_handlers(void) {
    dSetErrorHandler(&on_error);
    dSetDebugHandler(&on_debug);
    dSetMessageHandler(&on_message);
}

int odin_drain_message(char *buf, int size, int *errnum) {
    if (!ring_count) return -1;
    int level = ring[ring_head].level;
    *errnum = ring[ring_head].num;
    snprintf(buf, (size_t)size, "%s", ring[ring_head].text);
    ring_head = (ring_head + 1) % RING;
    ring_count--;
    return level;
}

void odin_test_message(int num, const char *msg) { dMessage(num, "%s", msg); }
