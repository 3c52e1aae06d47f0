/* A control planner's propagations checked in C (gui.planning through
 * virtual_world.core.checked_propagation.propagate_checked): each one odin_world_propagate's ODE calls
 * in its order, then the planner's validity rule on what it did, so that a search's step asks
 * Python for nothing between the state it starts from and the verdict on the state reached.
 *
 * The rule (OdinPlanRule, odin_step.h) is data Python builds once per search: a role for each
 * geom (by its OdinGeomInfo serial) and which pairs of roles may not touch (the planning
 * problem's forbidden contacts), and the tracked link whose origin must stay in a box and
 * whose body may not go faster than a bound on any axis. */
#include <ode/ode.h>
#include <math.h>
#include <stdint.h>
#include "odin_step.h"

static int geom_role(const OdinPlanRule *rule, dGeomID g) {
    const OdinGeomInfo *info = (const OdinGeomInfo *)dGeomGetData(g);
    long serial = info ? info->serial : -1;
    return (serial >= 0 && serial < rule->n_serials) ? rule->role_of_serial[serial] : 0;
}

/* 1 when a recorded pair is one of the rule's forbidden role pairs. */
static int forbidden_contact(const OdinWorld *w, const OdinPlanRule *rule) {
    for (int i = 0; i < w->n_records; ++i) {
        int a = geom_role(rule, w->records[i].g1), b = geom_role(rule, w->records[i].g2);
        if (rule->forbidden[a * rule->n_roles + b]) return 1;
    }
    return 0;
}

/* The tracked link's origin (m, world) and its body's linear velocity (m/s, world) in the
 * body state vector `state`, into out[0..6): the body's frame origin (its centre of mass less
 * R com), then plus R offset, R being odin_common.rotations' quaternion_to_matrix and each
 * product summed row by row, left to right. Every planning back end reads the tracked link
 * this way (TrackedLink); numpy's matrix product, which the Core's body_state and
 * PlanningProblem.tracked_origin use, may differ from it in the last bit (BLAS fuses). */
void odin_plan_tracked(const OdinPlanRule *rule, const double *state, double *out) {
    const double *body = state + 1 + (long)rule->tracked * ODIN_BODY_STATE_SIZE;
    double w = body[3], x = body[4], y = body[5], z = body[6];
    double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                   2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                   2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)};
    double origin[3];
    int centred = rule->com[0] == 0.0 && rule->com[1] == 0.0 && rule->com[2] == 0.0;
    if (centred && body[0] != 0.0 && body[1] != 0.0 && body[2] != 0.0) {
        origin[0] = body[0]; origin[1] = body[1]; origin[2] = body[2];
    } else {
        for (int k = 0; k < 3; ++k)
            origin[k] = body[k] - (r[3 * k] * rule->com[0] + r[3 * k + 1] * rule->com[1]
                                   + r[3 * k + 2] * rule->com[2]);
    }
    for (int k = 0; k < 3; ++k) {
        out[k] = origin[k] + (r[3 * k] * rule->offset[0] + r[3 * k + 1] * rule->offset[1]
                              + r[3 * k + 2] * rule->offset[2]);
        out[3 + k] = body[19 + k];
    }
}

/* 1 when tracked (odin_plan_tracked's six values) is inside the rule's box and speed bound;
 * a NaN is not. */
static int tracked_in_bounds(const OdinPlanRule *rule, const double *tracked) {
    for (int k = 0; k < 3; ++k) {
        if (!(rule->low[k] <= tracked[k] && tracked[k] <= rule->high[k])) return 0;
        if (!(fabs(tracked[3 + k]) <= rule->max_speed)) return 0;
    }
    return 1;
}

int odin_plan_propagate(OdinWorld *w, dBodyID *bodies, int n, const OdinPlanRule *rule,
                        const double *state_in, const OdinBodyForce *forces, int n_forces,
                        double h, int steps, int count, int stop_at_invalid,
                        double *states_out, long stride, double *tracked_out) {
    long size = 1 + (long)n * ODIN_BODY_STATE_SIZE + w->n_exempt;
    const double *from = state_in;
    for (int i = 0; i < count; ++i) {
        double *to = states_out + i * stride;
        int taken = odin_world_propagate_records(w, bodies, n, from, forces, n_forces, h, steps,
                                                 to);
        /* only state_in can be refused: every later one is a state ODE stepped to, which
         * the divergence guard keeps finite */
        if (taken < 0) return i == 0 ? taken : i;
        int invalid = forbidden_contact(w, rule);
        odin_world_clear_records(w);
        odin_plan_tracked(rule, to, tracked_out + 6 * (long)i);
        invalid = invalid || !tracked_in_bounds(rule, tracked_out + 6 * (long)i);
        to[size] = invalid ? 1.0 : 0.0;
        if (invalid && stop_at_invalid) return i + 1;
        from = to;
    }
    return count;
}
