/* arm.c: the C client of the four-language test (c_programs.rs): it commands the arm.
 * Connects to the arm and the arm gripper, prints "ready", and on the line "go" moves joint
 * JOINT to TARGET (arguments), waits for the outcome and until the arm reports the joint
 * there (at most 60 s), and prints "arm: done". On the line "report" it reads a fresh
 * state of each device and prints what it saw: "seen: <the six joint positions> gripper <state>". */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include <limber_client.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static int fail(const char *what, limber_code c) {
    fprintf(stderr, "arm: %s: %s: %s\n", what, limber_strerror(c), limber_last_error());
    return 1;
}

/* CLOCK_MONOTONIC in seconds. */
static double now_s(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

/* Waits for the line `word` on stdin; false at its end or on another line. */
static int expect_line(const char *word) {
    char line[64];
    if (!fgets(line, sizeof line, stdin)) return 0;
    line[strcspn(line, "\n")] = 0;
    return strcmp(line, word) == 0;
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: arm JOINT TARGET\n");
        return 2;
    }
    unsigned joint = (unsigned)atoi(argv[1]);
    double target = atof(argv[2]);
    limber_actarray *arm = NULL;
    limber_gripper *gripper = NULL;
    limber_code c = limber_actarray_connect("pioneer/actarray/0", NULL, 5000, &arm);
    if (c != LIMBER_CODE_OK) return fail("connect", c);
    if ((c = limber_gripper_connect("pioneer/gripper/1", NULL, 5000, &gripper)) != LIMBER_CODE_OK)
        return fail("connect the gripper", c);
    printf("ready\n");
    fflush(stdout);
    if (!expect_line("go")) return 1;

    limber_ticket ticket;
    uint32_t status = LIMBER_STATUS_OK;
    if ((c = limber_actarray_move_to(arm, joint, target, &ticket)) != LIMBER_CODE_OK) return fail("move_to", c);
    if ((c = limber_actarray_wait_outcome(arm, ticket, 5000, &status)) != LIMBER_CODE_OK)
        return fail("wait_outcome", c);
    printf("arm: move %s\n", limber_status_text(status));
    limber_actarray_data d;
    int there = 0;
    double deadline = now_s() + 60.0;
    while (!there && now_s() < deadline) {
        if ((c = limber_actarray_wait_state(arm, 2000, &d)) != LIMBER_CODE_OK) return fail("wait_state", c);
        there = fabs(d.actuators[joint].position - target) < 0.02 &&
                (d.actuators[joint].state & LIMBER_ACTSTATE_IDLE);
    }
    if (!there) {
        fprintf(stderr, "arm: joint %u did not reach %.3f within 60 s: at %.3f with state bits %u\n", joint, target,
                d.actuators[joint].position, d.actuators[joint].state);
        return 1;
    }
    printf("arm: done\n");
    fflush(stdout);

    if (!expect_line("report")) return 1;
    limber_gripper_data g;
    if ((c = limber_actarray_wait_state(arm, 2000, &d)) != LIMBER_CODE_OK) return fail("wait_state", c);
    if ((c = limber_gripper_wait_state(gripper, 2000, &g)) != LIMBER_CODE_OK) return fail("gripper wait_state", c);
    printf("seen:");
    for (unsigned j = 0; j < d.actuators_count; j++) printf(" %.9f", d.actuators[j].position);
    printf(" gripper %u\n", g.state);
    limber_gripper_disconnect(gripper);
    limber_actarray_disconnect(arm);
    return 0;
}
