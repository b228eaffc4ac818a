/* done.c: how a motion ended, from C. Moves joint 1 of the arm and waits for the motion's
 * result (limber_actarray_wait_done); then starts a long move, replaces
 * it at once with another, and waits for the first one's result. Prints
 * "reached: <sentence>", "error E tolerance T" and "first: <RESULT NAME>". */
#include <limber_client.h>

#include <math.h>
#include <stdio.h>

static int fail(const char *what, limber_code c) {
    fprintf(stderr, "done: %s: %s: %s\n", what, limber_strerror(c), limber_last_error());
    return 1;
}

int main(void) {
    limber_actarray *arm = NULL;
    limber_code c = limber_actarray_connect("pioneer/actarray/0", NULL, 5000, &arm);
    if (c != LIMBER_CODE_OK) return fail("connect", c);
    limber_actarray_geom geom;
    if ((c = limber_actarray_geometry(arm, 2000, &geom)) != LIMBER_CODE_OK) return fail("geometry", c);
    const unsigned joint = 1;
    double target = geom.actuators[joint].home + 0.3;
    if (target > geom.actuators[joint].max) target = geom.actuators[joint].home - 0.3;

    limber_ticket t;
    if ((c = limber_actarray_move_to(arm, joint, target, &t)) != LIMBER_CODE_OK) return fail("move_to", c);
    limber_done d;
    if ((c = limber_actarray_wait_done(arm, t, 60000, &d)) != LIMBER_CODE_OK)
        return fail("wait_done", c);
    if (d.result != LIMBER_RESULT_REACHED) {
        fprintf(stderr, "done: not reached: %s\n", d.sentence);
        return 1;
    }
    printf("reached: %s\n", d.sentence);
    printf("error %.6f tolerance %.6f\n", fabs(d.error[joint]), d.tolerance);

    limber_ticket first, second;
    double far = geom.actuators[joint].max, near = geom.actuators[joint].min;
    if ((c = limber_actarray_move_to(arm, joint, far, &first)) != LIMBER_CODE_OK) return fail("move_to", c);
    uint32_t status;
    if ((c = limber_actarray_wait_outcome(arm, first, 5000, &status)) != LIMBER_CODE_OK) return fail("outcome", c);
    if ((c = limber_actarray_move_to(arm, joint, near, &second)) != LIMBER_CODE_OK) return fail("move_to", c);
    if ((c = limber_actarray_wait_done(arm, first, 10000, &d)) != LIMBER_CODE_OK)
        return fail("wait_done", c);
    printf("first: %s\n", d.result == LIMBER_RESULT_PREEMPTED ? "PREEMPTED" : "other");
    if ((c = limber_actarray_wait_done(arm, second, 60000, &d)) != LIMBER_CODE_OK)
        return fail("wait_done", c);
    limber_actarray_disconnect(arm);
    return d.result == LIMBER_RESULT_REACHED ? 0 : 1;
}
