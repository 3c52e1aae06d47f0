/* Native baseline of the peers' rest<N> scenes (tools/bench/peers/scenes.py) for the per-body
 * cost plot and scale figures of bench_peers.py: N spheres (r 0.1 m, 1 kg) resting on a plane,
 * spread on a 0.3 m grid, stepped as Odin steps them (its world settings, broad phase and
 * contact order: ordered_contacts.h; QuickStep, 20 iterations, 1 ms).
 * Usage: rest_scene N STEPS WARMUP. Prints "SECONDS STEPS N": the seconds in the STEPS timed
 * steps, after WARMUP untimed ones. */
#include <math.h>
#include <ode/ode.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "ordered_contacts.h"

int main(int argc, char **argv) {
    if (argc != 4) { fprintf(stderr, "usage: rest_scene N STEPS WARMUP\n"); return 2; }
    int n = atoi(argv[1]), steps = atoi(argv[2]), warm = atoi(argv[3]);
    dInitODE2(0);
    dWorldID world = dWorldCreate();
    dSpaceID space = odin_space();
    dJointGroupID group = dJointGroupCreate(0);
    dWorldSetGravity(world, 0, 0, -9.81);
    dWorldSetERP(world, 0.2);
    dWorldSetCFM(world, 1e-5);
    dWorldSetContactSurfaceLayer(world, 0.001);
    dWorldSetQuickStepNumIterations(world, 20);
    dWorldSetLinearDampingThreshold(world, 0.01);
    dWorldSetAngularDampingThreshold(world, 0.01);
    number_geom(dCreatePlane(space, 0, 0, 1, 0));
    int side = (int)ceil(sqrt((double)n));
    for (int i = 0; i < n; ++i) {
        dBodyID b = dBodyCreate(world);
        dMass m;
        dMassSetSphereTotal(&m, 1.0, 0.1);
        dBodySetMass(b, &m);
        dBodySetPosition(b, (i % side) * 0.3 - side * 0.15, (i / side) * 0.3 - side * 0.15, 0.1);
        dGeomID g = dCreateSphere(space, 0.1);
        number_geom(g);
        dGeomSetBody(g, b);
    }
    struct timespec t0, t1;
    for (int s = 0; s < warm + steps; ++s) {
        if (s == warm) clock_gettime(CLOCK_MONOTONIC, &t0);
        collide_in_order(world, space, group);
        dWorldQuickStep(world, 0.001);
        dJointGroupEmpty(group);
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    printf("%.6f %d %d\n", (t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec), steps, n);
    dCloseODE();
    return 0;
}
