/* pick_block.c: pick up a block with a limb and its gripper, carry it and put it down,
 * in C with liblimber (the paper's Listing 2; README.md beside this file).
 *
 * Usage: pick_block [BLOCK_X BLOCK_Y]   (robot frame, m; default 0.38 0.10)
 * Exit status: 0 done, 2 the block is out of reach (the arm went home), 1 any other
 * failure (the message says which step and why). */
#define _POSIX_C_SOURCE 200809L
#include <limber_client.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define CONNECT_MS 5000
#define MOTION_MS 30000 /* the longest one motion may take */
#define REQUEST_MS 2000

static const double HANDLE_HEIGHT = 0.17; /* height above the floor to grab at */
static const double CLEARANCE = 0.05;     /* approach and lift 5 cm above it */

static int failed(const char *step, limber_code code) {
    fprintf(stderr, "pick_block: %s: %s (%s)\n", step, limber_strerror(code), limber_last_error());
    return 1;
}

static double now_ms(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

/* Waits for the outcome of a limb command, then until the limb stops moving.
 * Returns 0 there, 2 out of reach, 1 another failure. */
static int wait_limb(limber_limb *limb, const char *step, limber_code sent, limber_ticket ticket) {
    if (sent != LIMBER_CODE_OK) return failed(step, sent);
    uint32_t status = LIMBER_STATUS_OK;
    limber_code c = limber_limb_wait_outcome(limb, ticket, MOTION_MS, &status);
    if (c != LIMBER_CODE_OK && c != LIMBER_CODE_OUTCOME_MISSED) return failed(step, c);
    if (status == LIMBER_STATUS_OUT_OF_REACH) return 2;
    if (status != LIMBER_STATUS_OK && status != LIMBER_STATUS_CLAMPED) {
        fprintf(stderr, "pick_block: %s: refused: %s\n", step, limber_status_text(status));
        return 1;
    }
    limber_limb_data d;
    if ((c = limber_limb_state(limb, MOTION_MS, &d)) != LIMBER_CODE_OK) return failed(step, c);
    double deadline = now_ms() + MOTION_MS;
    while (d.state == LIMBER_LIMB_STATE_MOVING) {
        if (now_ms() > deadline) return failed(step, LIMBER_CODE_TIMEOUT);
        if ((c = limber_limb_wait_state(limb, MOTION_MS, &d)) != LIMBER_CODE_OK) return failed(step, c);
    }
    if (d.state == LIMBER_LIMB_STATE_OOR) return 2;
    if (d.state == LIMBER_LIMB_STATE_COLL) {
        fprintf(stderr, "pick_block: %s: the limb is blocked\n", step);
        return 1;
    }
    printf("%s: limb at (%.3f, %.3f, %.3f)\n", step, d.position.x, d.position.y, d.position.z);
    return 0;
}

/* Waits for the outcome of a gripper command, then until the gripper is `want`. */
static int wait_gripper(limber_gripper *g, const char *step, limber_code sent, limber_ticket ticket,
                        uint32_t want) {
    if (sent != LIMBER_CODE_OK) return failed(step, sent);
    uint32_t status = LIMBER_STATUS_OK;
    limber_code c = limber_gripper_wait_outcome(g, ticket, MOTION_MS, &status);
    if (c != LIMBER_CODE_OK && c != LIMBER_CODE_OUTCOME_MISSED) return failed(step, c);
    if (status != LIMBER_STATUS_OK) {
        fprintf(stderr, "pick_block: %s: refused: %s\n", step, limber_status_text(status));
        return 1;
    }
    limber_gripper_data d;
    if ((c = limber_gripper_state(g, MOTION_MS, &d)) != LIMBER_CODE_OK) return failed(step, c);
    double deadline = now_ms() + MOTION_MS;
    while (d.state != want) {
        if (now_ms() > deadline) return failed(step, LIMBER_CODE_TIMEOUT);
        if ((c = limber_gripper_wait_state(g, MOTION_MS, &d)) != LIMBER_CODE_OK) return failed(step, c);
    }
    printf("%s: gripper %s\n", step, want == LIMBER_GRIPPER_STATE_CLOSED ? "closed" : "open");
    return 0;
}

/* The end effector above (x, y) at height z, pointing down, its orientation vector
 * radially outward from the limb's base (what a 5-DOF arm can reach pointing down). */
static int move_to(limber_limb *limb, const limber_vec3 *base, const char *step, double x, double y,
                   double z) {
    double ox = x - base->x, oy = y - base->y, n = sqrt(ox * ox + oy * oy);
    limber_vec3 orientation = {n > 1e-9 ? ox / n : 1.0, n > 1e-9 ? oy / n : 0.0, 0.0};
    limber_vec3 position = {x, y, z}, down = {0.0, 0.0, -1.0};
    limber_ticket t;
    return wait_limb(limb, step, limber_limb_set_pose(limb, position, down, orientation, &t), t);
}

static int pick(limber_limb *limb, limber_gripper *g, double bx, double by, double dx, double dy) {
    limber_ticket t;
    limber_limb_geom geom;
    int rc;
    if ((rc = wait_limb(limb, "home", limber_limb_home(limb, &t), t))) return rc;
    limber_code c = limber_limb_geometry(limb, REQUEST_MS, &geom);
    if (c != LIMBER_CODE_OK) return failed("geometry", c);
    if ((rc = wait_gripper(g, "open", limber_gripper_open(g, &t), t, LIMBER_GRIPPER_STATE_OPEN))) return rc;
    if ((rc = move_to(limb, &geom.base_pos, "approach", bx, by, HANDLE_HEIGHT + CLEARANCE))) return rc;
    if ((rc = move_to(limb, &geom.base_pos, "descend", bx, by, HANDLE_HEIGHT))) return rc;
    if ((rc = wait_gripper(g, "grip", limber_gripper_close(g, &t), t, LIMBER_GRIPPER_STATE_CLOSED))) return rc;
    if ((rc = move_to(limb, &geom.base_pos, "lift", bx, by, HANDLE_HEIGHT + CLEARANCE))) return rc;
    if ((rc = move_to(limb, &geom.base_pos, "carry", dx, dy, HANDLE_HEIGHT + CLEARANCE))) return rc;
    if ((rc = move_to(limb, &geom.base_pos, "put down", dx, dy, HANDLE_HEIGHT))) return rc;
    if ((rc = wait_gripper(g, "release", limber_gripper_open(g, &t), t, LIMBER_GRIPPER_STATE_OPEN))) return rc;
    if ((rc = move_to(limb, &geom.base_pos, "retreat", dx, dy, HANDLE_HEIGHT + CLEARANCE))) return rc;
    return wait_limb(limb, "home again", limber_limb_home(limb, &t), t);
}

int main(int argc, char **argv) {
    double bx = 0.38, by = 0.10;
    if (argc == 3) {
        bx = atof(argv[1]);
        by = atof(argv[2]);
    } else if (argc != 1) {
        fprintf(stderr, "usage: pick_block [BLOCK_X BLOCK_Y]\n");
        return 1;
    }
    limber_limb *limb = NULL;
    limber_gripper *gripper = NULL;
    limber_code c = limber_limb_connect("pioneer/limb/0", NULL, CONNECT_MS, &limb);
    if (c != LIMBER_CODE_OK) return failed("connect", c);
    c = limber_gripper_connect("pioneer/gripper/1", NULL, CONNECT_MS, &gripper);
    if (c != LIMBER_CODE_OK) {
        limber_limb_disconnect(limb);
        return failed("connect", c);
    }
    int rc = pick(limb, gripper, bx, by, 0.38, -0.10);
    if (rc == 2) {
        printf("Target out of reach, terminating\n");
        limber_ticket t;
        wait_limb(limb, "home", limber_limb_home(limb, &t), t);
    } else if (rc == 0) {
        printf("done: block picked up and put down\n");
    }
    limber_gripper_disconnect(gripper);
    limber_limb_disconnect(limb);
    return rc;
}
