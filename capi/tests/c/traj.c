/* traj.c: a joint trajectory from C (limber_actarray_follow_trajectory). Moves the wrist
 * (joint 5) of simarm by 0.2 rad through a midpoint in 1 s, waits for the result
 * (limber_actarray_wait_done), then tries a trajectory whose times go backwards (refused
 * before anything is sent) and one naming a joint the arm lacks (refused by the driver).
 * Prints "reached: <sentence>", "error E tolerance T", "invalid: <reason>" and
 * "unknown joint: <status>". */
#include <limber_client.h>

#include <math.h>
#include <stdio.h>

static int fail(const char *what, limber_code c) {
    fprintf(stderr, "traj: %s: %s: %s\n", what, limber_strerror(c), limber_last_error());
    return 1;
}

int main(void) {
    limber_actarray *arm = NULL;
    limber_code c = limber_actarray_connect("simarm/actarray/0", NULL, 5000, &arm);
    if (c != LIMBER_CODE_OK) return fail("connect", c);
    limber_actarray_data d;
    if ((c = limber_actarray_wait_state(arm, 2000, &d)) != LIMBER_CODE_OK) return fail("wait_state", c);
    const uint32_t joints[] = {5};
    const double q = d.actuators[5].position;
    const double times[] = {0.5, 1.0};
    const double positions[] = {q + 0.1, q + 0.2};
    const double velocities[] = {0.3, 0.0};
    const double goal_tolerance[] = {0.001};
    limber_ticket t;
    c = limber_actarray_follow_trajectory(arm, joints, 1, times, 2, positions, velocities, NULL,
                                          NULL, goal_tolerance, 0.0, 0, &t);
    if (c != LIMBER_CODE_OK) return fail("follow_trajectory", c);
    limber_done done;
    if ((c = limber_actarray_wait_done(arm, t, 20000, &done)) != LIMBER_CODE_OK)
        return fail("wait_done", c);
    if (done.result != LIMBER_RESULT_REACHED) {
        fprintf(stderr, "traj: not reached: %s\n", done.sentence);
        return 1;
    }
    printf("reached: %s\n", done.sentence);
    printf("error %.6f tolerance %.6f\n", fabs(done.error[5]), done.tolerance);

    const double backwards[] = {1.0, 0.5};
    c = limber_actarray_follow_trajectory(arm, joints, 1, backwards, 2, positions, NULL, NULL,
                                          NULL, NULL, 0.0, 0, &t);
    if (c != LIMBER_CODE_INVALID_VALUE) return fail("a backwards trajectory accepted", c);
    printf("invalid: %s\n", limber_last_error());

    const uint32_t unknown[] = {0, 20};
    const double two[] = {0.0, 0.0};
    c = limber_actarray_follow_trajectory(arm, unknown, 2, times, 1, two, NULL, NULL, NULL, NULL,
                                          0.0, 0, &t);
    if (c != LIMBER_CODE_OK) return fail("follow_trajectory", c);
    uint32_t status;
    if ((c = limber_actarray_wait_outcome(arm, t, 5000, &status)) != LIMBER_CODE_OK)
        return fail("wait_outcome", c);
    printf("unknown joint: %s\n", limber_status_name(status));
    limber_actarray_disconnect(arm);
    return status == LIMBER_STATUS_UNKNOWN_JOINT ? 0 : 1;
}
