/* paths.c: limb paths and gripper goals from C (issue 28), on simarm with its block. The
 * tool over the table; a straight line (limber_limb_line) waited for; a line out of reach
 * refused, and the limb state saying where; a PTP to the block's grasp point; a gripper goal
 * that closes on the block and stalls with the object present. Prints "line: <sentence>",
 * "refused: <STATUS> at <percent> (x, y, z)", "ptp: <sentence>", "goal: <RESULT> <CAUSE>". */
#include <limber_client.h>

#include <stdio.h>

static int fail(const char *what, limber_code c) {
    fprintf(stderr, "paths: %s: %s: %s\n", what, limber_strerror(c), limber_last_error());
    return 1;
}

int main(void) {
    limber_limb *limb = NULL;
    limber_gripper *grip = NULL;
    limber_code c = limber_limb_connect("simarm/limb/0", NULL, 5000, &limb);
    if (c != LIMBER_CODE_OK) return fail("connect limb", c);
    if ((c = limber_gripper_connect("simarm/gripper/0", NULL, 5000, &grip)) != LIMBER_CODE_OK)
        return fail("connect gripper", c);
    const limber_vec3 down = {0, 0, -1}, forward = {1, 0, 0};
    limber_ticket t;
    limber_done d;

    if ((c = limber_limb_set_pose(limb, (limber_vec3){0.4, 0, 0.3}, down, forward, &t)))
        return fail("set_pose", c);
    if ((c = limber_limb_wait_done(limb, t, 60000, &d))) return fail("wait_done", c);

    /* A straight line, the orientation kept (NULL, NULL), at 0.2 m/s. */
    if ((c = limber_limb_line(limb, (limber_vec3){0.35, 0.15, 0.22}, NULL, NULL, 0.2, &t)))
        return fail("line", c);
    if ((c = limber_limb_wait_done(limb, t, 60000, &d))) return fail("wait_done", c);
    printf("line: %s\n", d.sentence);
    if (d.result != LIMBER_RESULT_REACHED) return 1;

    /* Out of reach: refused before anything moves; the state says where. */
    if ((c = limber_limb_line(limb, (limber_vec3){2, 0, 0.3}, NULL, NULL, 0, &t)))
        return fail("line", c);
    uint32_t status;
    if ((c = limber_limb_wait_outcome(limb, t, 5000, &status))) return fail("outcome", c);
    limber_limb_data s;
    if ((c = limber_limb_state(limb, 2000, &s))) return fail("state", c);
    if (s.refused_kind != LIMBER_LIMB_CMD_LINE) return 1;
    printf("refused: %s at %.0f%% (%.3f, %.3f, %.3f)\n", limber_status_name(status),
           s.refused_fraction * 100, s.refused_at.x, s.refused_at.y, s.refused_at.z);

    /* The fingers open, then a PTP to the block's grasp point, pointing down. */
    if ((c = limber_gripper_goal(grip, 1.0, 0, 0, &t))) return fail("goal", c);
    if ((c = limber_gripper_wait_done(grip, t, 60000, &d))) return fail("wait_done", c);
    if ((c = limber_limb_ptp(limb, (limber_vec3){0.36, 0.06, 0.17}, &down, &forward, 0, &t)))
        return fail("ptp", c);
    if ((c = limber_limb_wait_done(limb, t, 60000, &d))) return fail("wait_done", c);
    printf("ptp: %s\n", d.sentence);
    if (d.result != LIMBER_RESULT_REACHED) return 1;

    /* Closing on the block: stalled on it, the beams see it. */
    if ((c = limber_gripper_goal(grip, 0.0, 5.0, 0, &t))) return fail("goal", c);
    if ((c = limber_gripper_wait_done(grip, t, 60000, &d))) return fail("wait_done", c);
    printf("goal: %s %s\n", d.result == LIMBER_RESULT_STALLED ? "STALLED" : "other",
           limber_status_name(d.cause));
    limber_gripper_disconnect(grip);
    limber_limb_disconnect(limb);
    return 0;
}
