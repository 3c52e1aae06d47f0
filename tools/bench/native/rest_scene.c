/* Native baseline of the peers' rest<N> scenes (tools/bench/peers/scenes.py): N spheres (r 0.1
 * m, 1 kg) resting on a plane, spread on a 0.3 m grid, stepped as Odin steps them (its world
 * settings, broad phase and contact order: ordered_contacts.h; QuickStep, 20 iterations, 1 ms).
 * bench_peers.py runs it as Odin has it for the per-body cost plot and scale figures;
 * bench_levers.py changes one of ODE's levers at a time (issue 14).
 *
 * Usage: rest_scene N STEPS WARMUP [SPACE AUTO_DISABLE THREADS]
 *   SPACE         sap (Odin's, the default), hash (ODE's hash space, levels -3..3 as Odin had
 *                 them) or quadtree (ODE's quadtree over the grid, depth 7);
 *   AUTO_DISABLE  0 (the default), or 1: ODE's auto-disabling with its default thresholds
 *                 (0.01 m/s, 0.01 rad/s, 10 steps), the bodies left where they settled;
 *   THREADS       ODE's island threading: 1 (the default) steps on the caller's thread, as
 *                 Odin does; k > 1 a pool of k threads serving dWorldQuickStep's islands.
 * Prints one line: "SECONDS STEPS N ENABLED DRIFT": the seconds of the STEPS timed steps
 * after WARMUP untimed ones, the bodies still enabled at the end, and the largest distance
 * (m) of a sphere's centre from where it started. */
#include <math.h>
#include <ode/ode.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "ordered_contacts.h"

static dSpaceID make_space(const char *kind, int side) {
    if (strcmp(kind, "sap") == 0) return odin_space();
    if (strcmp(kind, "hash") == 0) {
        dSpaceID space = dHashSpaceCreate(0);
        dHashSpaceSetLevels(space, -3, 3);
        return space;
    }
    if (strcmp(kind, "quadtree") == 0) {
        /* ODE's quadtree splits x and y (z up, as Odin's ground); extents are half-sizes */
        dVector3 centre = {0, 0, 0}, extents = {side * 0.15 + 1.0, side * 0.15 + 1.0, 2.0};
        return dQuadTreeSpaceCreate(0, centre, extents, 7);
    }
    fprintf(stderr, "rest_scene: SPACE %s: choose sap, hash or quadtree\n", kind);
    exit(2);
}

int main(int argc, char **argv) {
    if (argc != 4 && argc != 7) {
        fprintf(stderr, "usage: rest_scene N STEPS WARMUP [SPACE AUTO_DISABLE THREADS]\n");
        return 2;
    }
    int n = atoi(argv[1]), steps = atoi(argv[2]), warm = atoi(argv[3]);
    const char *space_kind = argc == 7 ? argv[4] : "sap";
    int auto_disable = argc == 7 ? atoi(argv[5]) : 0, threads = argc == 7 ? atoi(argv[6]) : 1;
    if (n < 1 || steps < 1 || warm < 0 || threads < 1) {
        fprintf(stderr, "rest_scene: N, STEPS and THREADS must be positive, WARMUP not "
                "negative\n");
        return 2;
    }
    dInitODE2(0);
    dAllocateODEDataForThread(dAllocateMaskAll);
    dWorldID world = odin_world();
    int side = (int)ceil(sqrt((double)n));
    dSpaceID space = make_space(space_kind, side);
    dJointGroupID group = dJointGroupCreate(0);
    dWorldSetAutoDisableFlag(world, auto_disable);
    dThreadingImplementationID threading = NULL;
    dThreadingThreadPoolID pool = NULL;
    if (threads > 1) {
        threading = dThreadingAllocateMultiThreadedImplementation();
        pool = dThreadingAllocateThreadPool(threads, 0, dAllocateFlagBasicData, NULL);
        dThreadingThreadPoolServeMultiThreadedImplementation(pool, threading);
        dWorldSetStepIslandsProcessingMaxThreadCount(world, threads);
        dWorldSetStepThreadingImplementation(
            world, dThreadingImplementationGetFunctions(threading), threading);
    }
    number_geom(dCreatePlane(space, 0, 0, 1, 0));
    dBodyID *bodies = malloc((size_t)n * sizeof(dBodyID));
    double *start = malloc((size_t)n * 3 * sizeof(double));
    if (!bodies || !start) abort();
    for (int i = 0; i < n; ++i) {
        dBodyID b = dBodyCreate(world);
        dMass m;
        dMassSetSphereTotal(&m, 1.0, 0.1);
        dBodySetMass(b, &m);
        start[3 * i] = (i % side) * 0.3 - side * 0.15;
        start[3 * i + 1] = (i / side) * 0.3 - side * 0.15;
        start[3 * i + 2] = 0.1;
        dBodySetPosition(b, start[3 * i], start[3 * i + 1], start[3 * i + 2]);
        dGeomID g = dCreateSphere(space, 0.1);
        number_geom(g);
        dGeomSetBody(g, b);
        bodies[i] = b;
    }
    struct timespec t0, t1;
    for (int s = 0; s < warm + steps; ++s) {
        if (s == warm) clock_gettime(CLOCK_MONOTONIC, &t0);
        collide_in_order(world, space, group);
        dWorldQuickStep(world, 0.001);
        dJointGroupEmpty(group);
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    int enabled = 0;
    double drift = 0;
    for (int i = 0; i < n; ++i) {
        const dReal *p = dBodyGetPosition(bodies[i]);
        double dx = p[0] - start[3 * i], dy = p[1] - start[3 * i + 1], dz = p[2] - start[3 * i + 2];
        drift = fmax(drift, sqrt(dx * dx + dy * dy + dz * dz));
        enabled += dBodyIsEnabled(bodies[i]) != 0;
    }
    printf("%.6f %d %d %d %.9g\n", (t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec),
           steps, n, enabled, drift);
    if (threading) {
        dThreadingImplementationShutdownProcessing(threading);
        dThreadingFreeThreadPool(pool);
        dWorldSetStepThreadingImplementation(world, NULL, NULL);
        dThreadingFreeImplementation(threading);
    }
    free(bodies);
    free(start);
    dCloseODE();
    return 0;
}
