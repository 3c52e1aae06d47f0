/* What Odin's step loop does, in plain C for the native baselines: its world settings
 * (odin_world) and broad phase (odin_space), and what it does with colliding pairs: every
 * geom carries its serial (creation order, from 1) as its data; the near-callback collides each
 * pair with the lower serial first and keeps its contacts; after the pass the pairs are sorted
 * by (serial 1, serial 2) and their contact joints made in that order (odin_step.c's
 * make_contacts), so the solver meets the same constraints in the same order whatever order
 * the broad phase found the pairs in. mu 1, Approx1 friction, no bounce. */
#ifndef ORDERED_CONTACTS_H
#define ORDERED_CONTACTS_H
#include <ode/ode.h>
#include <stdint.h>
#include <stdlib.h>

#define MAX_PAIR_CONTACTS 3

typedef struct { uint64_t key; dGeomID g1, g2; int n; dContactGeom c[MAX_PAIR_CONTACTS]; } Pair;

static Pair *pairs;
static int n_pairs, cap_pairs;

static long serial_of(dGeomID g) { return (long)(intptr_t)dGeomGetData(g); }

static void keep_pair(void *data, dGeomID o1, dGeomID o2) {
    (void)data;
    if (serial_of(o1) > serial_of(o2)) { dGeomID t = o1; o1 = o2; o2 = t; }
    dBodyID b1 = dGeomGetBody(o1), b2 = dGeomGetBody(o2);
    if (b1 == b2) return;
    if (b1 && b2 && dAreConnectedExcluding(b1, b2, dJointTypeContact)) return;
    if (n_pairs == cap_pairs) {
        cap_pairs = cap_pairs ? 2 * cap_pairs : 256;
        pairs = realloc(pairs, (size_t)cap_pairs * sizeof(Pair));
        if (!pairs) abort();
    }
    Pair *p = &pairs[n_pairs];
    p->n = dCollide(o1, o2, MAX_PAIR_CONTACTS, p->c, sizeof(dContactGeom));
    if (p->n <= 0) return;
    p->g1 = o1; p->g2 = o2;
    p->key = (uint64_t)serial_of(o1) << 32 | (uint64_t)(uint32_t)serial_of(o2);
    n_pairs++;
}

static int by_key(const void *a, const void *b) {
    uint64_t x = ((const Pair *)a)->key, y = ((const Pair *)b)->key;
    return x < y ? -1 : x > y;
}

/* Collides `space` and makes the contact joints in serial order; returns the contacts made.
 * Not inlined: bench_core counts its instructions by name (callgrind). */
__attribute__((noinline)) int collide_in_order(dWorldID world, dSpaceID space, dJointGroupID group) {
    n_pairs = 0;
    dSpaceCollide(space, 0, &keep_pair);
    qsort(pairs, (size_t)n_pairs, sizeof(Pair), by_key);
    int made = 0;
    for (int k = 0; k < n_pairs; ++k) {
        dBodyID b1 = dGeomGetBody(pairs[k].g1), b2 = dGeomGetBody(pairs[k].g2);
        for (int i = 0; i < pairs[k].n; ++i) {
            dContact c = {0};
            c.surface.mode = dContactApprox1;
            c.surface.mu = 1.0;
            c.surface.bounce_vel = 0.1;
            c.geom = pairs[k].c[i];
            dJointAttach(dJointCreateContact(world, group, &c), b1, b2);
        }
        made += pairs[k].n;
    }
    return made;
}

/* A world with Odin's default settings (odin_common.world_parameters; QuickStep's 20
 * iterations: the scenes step with dWorldQuickStep). */
static dWorldID odin_world(void) {
    dWorldID world = dWorldCreate();
    dWorldSetGravity(world, 0, 0, -9.81);
    dWorldSetERP(world, 0.2);
    dWorldSetCFM(world, 1e-5);
    dWorldSetContactSurfaceLayer(world, 0.001);
    dWorldSetQuickStepNumIterations(world, 20);
    dWorldSetLinearDampingThreshold(world, 0.01);
    dWorldSetAngularDampingThreshold(world, 0.01);
    return world;
}

/* The broad phase Odin collides with (virtual_world.ode.handles.new_space). */
static dSpaceID odin_space(void) { return dSweepAndPruneSpaceCreate(0, dSAP_AXES_XYZ); }

/* A geom's serial, given in creation order as Odin's scenes do. */
static void number_geom(dGeomID g) {
    static long next = 1;
    dGeomSetData(g, (void *)(intptr_t)next++);
}
#endif
