/* The geometric planner's collision queries (gui.planning.geometric through
 * virtual_world.core.probe): whether the geoms of some objects touch anything on their present
 * poses, with the step's rules for which pairs may touch (odin_pair_never_touches), and how far
 * capsules or boxes bounding them can grow before they touch anything else. Nothing is recorded, no
 * contact joint is made, nothing is stepped; the world's records are not touched. */
#include <ode/ode.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "odin_step.h"

/* One query's state, passed to ODE's near-callback through dSpaceCollide2's data. */
typedef struct {
    dGeomID geom;            /* the geom asked about (a listed geom, or the probe) */
    const uintptr_t *skip;   /* sorted addresses of geoms the query does not ask against */
    int n_skip;
    int probe;               /* 1: geom is a probe of no object (every other geom may touch it) */
    int touching;            /* set at the first touching pair; later pairs are not asked */
    dGeomID other;
} Ask;

static int skipped(const Ask *ask, dGeomID g) {
    uintptr_t key = (uintptr_t)g;
    int low = 0, high = ask->n_skip - 1;
    while (low <= high) {
        int mid = low + (high - low) / 2;
        if (ask->skip[mid] == key) return 1;
        if (ask->skip[mid] < key) low = mid + 1;
        else high = mid - 1;
    }
    return 0;
}

/* The classes ODE collides a probe with (a box's or a capsule's colliders): a probe meeting a
 * geom of another class (a cylinder, a convex, a heightfield) cannot be asked, and is taken to
 * touch it whenever their boxes overlap (a clearance is a lower bound: too small is safe, too
 * large is not). */
static int probe_collides_with(dGeomID g) {
    switch (dGeomGetClass(g)) {
    case dSphereClass: case dBoxClass: case dCapsuleClass: case dPlaneClass:
    case dTriMeshClass:
        return 1;
    default:
        return 0;
    }
}

static void ask_pair(void *data, dGeomID o1, dGeomID o2) {
    Ask *ask = (Ask *)data;
    if (ask->touching) return;
    dGeomID other = o1 == ask->geom ? o2 : o1;
    if (dGeomIsSpace(other)) { /* a space inside the world's: asked through */
        dSpaceCollide2(ask->geom, other, ask, &ask_pair);
        return;
    }
    if (other == ask->geom || (ask->n_skip && skipped(ask, other))) return;
    if (!ask->probe && odin_pair_never_touches(ask->geom, other)) return;
    if (ask->probe && !probe_collides_with(other)) {
        ask->touching = 1;
        ask->other = other;
        return;
    }
    dContactGeom contact[1];
    if (dCollide(ask->geom, other, 1, contact, sizeof(dContactGeom)) > 0) {
        ask->touching = 1;
        ask->other = other;
    }
}

int odin_geoms_touching(OdinWorld *w, const dGeomID *geoms, int n, dGeomID *hit) {
    Ask ask;
    memset(&ask, 0, sizeof ask);
    for (int i = 0; i < n; ++i) {
        ask.geom = geoms[i];
        dSpaceCollide2(geoms[i], (dGeomID)w->space, &ask, &ask_pair);
        if (ask.touching) {
            hit[0] = geoms[i];
            hit[1] = ask.other;
            return 1;
        }
    }
    return 0;
}

/* Puts the capsule probe along the segment a-b (m, world), its radius r + grown. */
static void place_capsule(dGeomID probe, const double *capsule, double grown) {
    const double *a = capsule, *b = capsule + 3;
    double axis[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double length = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    dMatrix3 R;
    if (length > 1e-12) dRFromZAxis(R, axis[0], axis[1], axis[2]);
    else dRSetIdentity(R);
    dGeomCapsuleSetParams(probe, capsule[6] + grown, length);
    dGeomSetPosition(probe, (a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2);
    dGeomSetRotation(probe, R);
}

/* Puts the box probe at its centre and rotation (row by row), its half sides + grown. */
static void place_box(dGeomID probe, const double *box, double grown) {
    const double *c = box, *r = box + 3, *half = box + 12;
    dMatrix3 R = {r[0], r[1], r[2], 0.0, r[3], r[4], r[5], 0.0, r[6], r[7], r[8], 0.0};
    dGeomBoxSetLengths(probe, 2 * (half[0] + grown), 2 * (half[1] + grown),
                       2 * (half[2] + grown));
    dGeomSetPosition(probe, c[0], c[1], c[2]);
    dGeomSetRotation(probe, R);
}

/* Whether bound (ODIN_BOUND_VALUES values) grown by `grown` touches anything asked. */
static int bound_touches(OdinWorld *w, Ask *ask, dGeomID capsule, dGeomID box,
                         const double *bound, double grown) {
    if (bound[0] == ODIN_BOUND_BOX) {
        ask->geom = box;
        place_box(box, bound + 1, grown);
    } else {
        ask->geom = capsule;
        place_capsule(capsule, bound + 1, grown);
    }
    ask->touching = 0;
    dSpaceCollide2(ask->geom, (dGeomID)w->space, ask, &ask_pair);
    return ask->touching;
}

/* The index in [first, n_tiers] of the first tier (descending) from `first` on at which the
 * bound touches nothing asked (n_tiers: none), searched from the index `hint` outwards (a
 * bound's clearance changes little from one query to the next: about two probes), then by
 * halves. */
static int first_clear_tier(OdinWorld *w, Ask *ask, dGeomID capsule, dGeomID box,
                            const double *bound, const double *tiers, int n_tiers, int hint,
                            int first) {
    int low = first, high = n_tiers; /* the answer is in [low, high] */
    if (hint < first) hint = first;
    if (hint >= n_tiers) hint = n_tiers - 1;
    if (bound_touches(w, ask, capsule, box, bound, tiers[hint])) {
        low = hint + 1;          /* clear, if anywhere, at a smaller tier */
        for (int step = 1; low + step - 1 < n_tiers; step *= 2) {
            int at = low + step - 1;
            if (!bound_touches(w, ask, capsule, box, bound, tiers[at])) { high = at; break; }
            low = at + 1;
        }
    } else {
        high = hint;             /* clear here: maybe at a larger tier too */
        for (int step = 1; high - step >= first; step *= 2) {
            int at = high - step;
            if (bound_touches(w, ask, capsule, box, bound, tiers[at])) { low = at + 1; break; }
            high = at;
        }
    }
    while (low < high) {
        int mid = low + (high - low) / 2;
        if (bound_touches(w, ask, capsule, box, bound, tiers[mid])) low = mid + 1;
        else high = mid;
    }
    return low;
}

void odin_bounds_clearance(OdinWorld *w, const double *bounds, int n, const double *tiers,
                           int n_tiers, const uintptr_t *skip, int n_skip, const int *firsts,
                           int *hints, double *out) {
    Ask ask;
    memset(&ask, 0, sizeof ask);
    dGeomID capsule = dCreateCapsule(0, 1.0, 1.0), box = dCreateBox(0, 1.0, 1.0, 1.0);
    ask.probe = 1;
    ask.skip = skip;
    ask.n_skip = n_skip;
    for (int i = 0; i < n; ++i) {
        int found = first_clear_tier(w, &ask, capsule, box, bounds + ODIN_BOUND_VALUES * i, tiers,
                                     n_tiers, hints[i], firsts[i]);
        out[i] = found < n_tiers ? tiers[found] : 0.0;
        hints[i] = found;
    }
    dGeomDestroy(capsule);
    dGeomDestroy(box);
}

void odin_place_bodies(dBodyID *bodies, int n, const double *poses) {
    for (int i = 0; i < n; ++i) {
        const double *p = poses + 12 * i, *r = p + 3;
        dMatrix3 R = {r[0], r[1], r[2], 0.0, r[3], r[4], r[5], 0.0, r[6], r[7], r[8], 0.0};
        dBodySetPosition(bodies[i], p[0], p[1], p[2]);
        dBodySetRotation(bodies[i], R);
    }
}
