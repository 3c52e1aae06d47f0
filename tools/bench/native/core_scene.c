/* Native baseline for bench_core.py: the same scene and step loop as the Odin Core, in plain C
 * over libode (the same broad phase, contacts made in the same order: ordered_contacts.h).
 * Usage: core_scene MODE STEPS NFORCES NMOTORS [CHECKPOINT...] (MODE 0 spheres on a plane,
 * 1 pile inside four walls). Prints the seconds spent in the step loop and the last
 * step's contacts on one line, then the final pose of each of the 100 bodies, one a line:
 * x y z qw qx qy qz (%.17g, which reads back as the same double), for bench_core.py and
 * bench_portal.py to compare with Odin's. Before that, after each CHECKPOINT-th step, a line
 * "after CHECKPOINT CONTACTS" and the 100 poses of that moment (the loop's time then includes
 * the printing: for checks, not timing). */
#include <ode/ode.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "ordered_contacts.h"

static dWorldID world;
static dJointGroupID group;
static int contacts_last;

static void print_poses(dBodyID *bodies) {
    for (int i = 0; i < 100; ++i) {
        const dReal *p = dBodyGetPosition(bodies[i]), *q = dBodyGetQuaternion(bodies[i]);
        printf("%.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", p[0], p[1], p[2], q[0], q[1], q[2], q[3]);
    }
}

static void wall(dSpaceID space, double x, double y, double z, double lx, double ly, double lz) {
    dGeomID g = dCreateBox(space, lx, ly, lz);
    number_geom(g);
    dGeomSetPosition(g, x, y, z);
}

int main(int argc, char **argv) {
    if (argc < 5) { fprintf(stderr, "usage: core_scene MODE STEPS NFORCES NMOTORS [CHECKPOINT...]\n"); return 2; }
    int mode = atoi(argv[1]), steps = atoi(argv[2]), nforces = atoi(argv[3]), nmotors = atoi(argv[4]);
    dInitODE2(0);
    world = odin_world();
    dSpaceID space = odin_space();
    group = dJointGroupCreate(0);
    wall(space, 0, 0, -0.5, 20, 20, 1);
    if (mode == 1) {
        wall(space, 0.65, 0, 1, 0.2, 1.5, 2);
        wall(space, -0.65, 0, 1, 0.2, 1.5, 2);
        wall(space, 0, 0.65, 1, 1.5, 0.2, 2);
        wall(space, 0, -0.65, 1, 1.5, 0.2, 2);
    }
    dBodyID bodies[100];
    for (int i = 0; i < 100; ++i) {
        double x, y, z;
        if (mode == 0) { x = (i % 10) * 0.25 - 1.125; y = (i / 10) * 0.25 - 1.125; z = 0.5; }
        else { int layer = i / 25; double o = (layer % 2) ? 0.06 : 0.0; x = (i % 5) * 0.21 - 0.42 + o + 0.001 * (i % 7); y = ((i / 5) % 5) * 0.21 - 0.42 + o; z = 0.15 + layer * 0.21; }
        dBodyID b = dBodyCreate(world);
        dMass m;
        dMassSetSphereTotal(&m, 1.0, 0.1);
        dBodySetMass(b, &m);
        dBodySetPosition(b, x, y, z);
        dGeomID g = dCreateSphere(space, 0.1);
        number_geom(g);
        dGeomSetBody(g, b);
        bodies[i] = b;
    }
    dJointID motors[100];
    for (int i = 0; i < nmotors; ++i) {
        dJointID j = dJointCreateAMotor(world, 0);
        dJointAttach(j, bodies[i], 0);
        dJointSetAMotorMode(j, dAMotorUser);
        dJointSetAMotorNumAxes(j, 1);
        dJointSetAMotorAxis(j, 0, 1, 0, 0, 1);
        dJointSetAMotorParam(j, dParamFMax, dInfinity);
        motors[i] = j;
    }
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (int s = 0; s < steps; ++s) {
        contacts_last = collide_in_order(world, space, group);
        for (int i = 0; i < nforces; ++i) dBodyAddForce(bodies[i % 100], 0.0, 0.0, 0.5);
        for (int i = 0; i < nmotors; ++i) dJointSetAMotorParam(motors[i], dParamVel, 0.5);
        dWorldQuickStep(world, 0.001);
        dJointGroupEmpty(group);
        for (int k = 5; k < argc; ++k)
            if (atoi(argv[k]) == s + 1) { printf("after %d %d\n", s + 1, contacts_last); print_poses(bodies); }
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    printf("%.6f %d\n", (t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec), contacts_last);
    print_poses(bodies);
    dCloseODE();
    return 0;
}
