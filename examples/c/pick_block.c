/* pick_block.c: find a block with the laser, pick it up with a limb and its gripper,
 * carry it and put it down, in C with liblimber (the paper's Listing 2; README.md beside
 * this file).
 *
 * Usage: pick_block [LIMB GRIPPER LASER]  (default pioneer/limb/0 pioneer/gripper/1
 * pioneer/ranger/0)
 * Exit status: 0 done, 2 the block is out of reach (the arm went home), 1 any other
 * failure (the message says which step and why). */
#define _POSIX_C_SOURCE 200809L
#include <limber_client.h>

#include <math.h>
#include <stdio.h>
#include <time.h>

#define CONNECT_MS 5000
#define MOTION_MS 30000 /* the longest one motion may take */
#define REQUEST_MS 2000

static const double HANDLE_HEIGHT = 0.17; /* height above the floor to grab at */
static const double CLEARANCE = 0.05;     /* approach and lift 5 cm above it */
static const double BLOCK_RADIUS = 0.02;  /* from the closest point seen to the centre */

/* Where the laser found the block: its centre and the orientation vector. */
struct found {
    double cx, cy, ox, oy;
};

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
    if (!limber_status_is_carried_out(status)) {
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

/* The paper's lines 13-40: the closest point of the laser's scan, in the robot frame by
 * the laser's pose; the block's centre BLOCK_RADIUS further along the same beam; the
 * orientation vector from the closest point to the centre. */
static int find_block(limber_ranger *laser, struct found *f) {
    limber_ranger_geom geom;
    limber_ranger_data scan;
    limber_code c = limber_ranger_geometry(laser, REQUEST_MS, &geom);
    if (c != LIMBER_CODE_OK) return failed("laser geometry", c);
    if ((c = limber_ranger_state(laser, CONNECT_MS, &scan)) != LIMBER_CODE_OK) return failed("scan", c);
    uint32_t min_index = 0;
    for (uint32_t i = 1; i < scan.ranges_count; ++i)
        if (scan.ranges[i] < scan.ranges[min_index]) min_index = i;
    double bearing = 0.0, px = 0.0, py = 0.0;
    if ((c = limber_ranger_point(&scan, min_index, &bearing, &px, &py)) != LIMBER_CODE_OK)
        return failed("scan", c);
    double closest_x = px + geom.pose.position.x, closest_y = py + geom.pose.position.y;
    double pre_range = scan.ranges[min_index] + BLOCK_RADIUS;
    f->cx = pre_range * cos(bearing) + geom.pose.position.x;
    f->cy = pre_range * sin(bearing) + geom.pose.position.y;
    f->ox = f->cx - closest_x;
    f->oy = f->cy - closest_y;
    printf("found the block at (%.3f, %.3f)\n", f->cx, f->cy);
    return 0;
}

/* The end effector above (x, y) at height z, pointing down, along the orientation vector
 * the laser gave. */
static int move_to(limber_limb *limb, const struct found *f, const char *step, double x, double y,
                   double z) {
    limber_vec3 orientation = {f->ox, f->oy, 0.0};
    limber_vec3 position = {x, y, z}, down = {0.0, 0.0, -1.0};
    limber_ticket t;
    return wait_limb(limb, step, limber_limb_set_pose(limb, position, down, orientation, &t), t);
}

static int pick(limber_limb *limb, limber_gripper *g, limber_ranger *laser, double dx, double dy) {
    limber_ticket t;
    limber_limb_geom geom;
    struct found f;
    int rc;
    if ((rc = wait_limb(limb, "home", limber_limb_home(limb, &t), t))) return rc;
    limber_code c = limber_limb_geometry(limb, REQUEST_MS, &geom);
    if (c != LIMBER_CODE_OK) return failed("geometry", c);
    if ((rc = find_block(laser, &f))) return rc;
    double bx = f.cx, by = f.cy;
    if ((rc = wait_gripper(g, "open", limber_gripper_open(g, &t), t, LIMBER_GRIPPER_STATE_OPEN))) return rc;
    if ((rc = move_to(limb, &f, "approach", bx, by, HANDLE_HEIGHT + CLEARANCE))) return rc;
    if ((rc = move_to(limb, &f, "descend", bx, by, HANDLE_HEIGHT))) return rc;
    if ((rc = wait_gripper(g, "grip", limber_gripper_close(g, &t), t, LIMBER_GRIPPER_STATE_CLOSED))) return rc;
    if ((rc = move_to(limb, &f, "lift", bx, by, HANDLE_HEIGHT + CLEARANCE))) return rc;
    if ((rc = move_to(limb, &f, "carry", dx, dy, HANDLE_HEIGHT + CLEARANCE))) return rc;
    if ((rc = move_to(limb, &f, "put down", dx, dy, HANDLE_HEIGHT))) return rc;
    if ((rc = wait_gripper(g, "release", limber_gripper_open(g, &t), t, LIMBER_GRIPPER_STATE_OPEN))) return rc;
    if ((rc = move_to(limb, &f, "retreat", dx, dy, HANDLE_HEIGHT + CLEARANCE))) return rc;
    return wait_limb(limb, "home again", limber_limb_home(limb, &t), t);
}

int main(int argc, char **argv) {
    const char *limb_name = "pioneer/limb/0", *gripper_name = "pioneer/gripper/1",
               *laser_name = "pioneer/ranger/0";
    if (argc == 4) {
        limb_name = argv[1];
        gripper_name = argv[2];
        laser_name = argv[3];
    } else if (argc != 1) {
        fprintf(stderr, "usage: pick_block [LIMB GRIPPER LASER]\n");
        return 1;
    }
    limber_limb *limb = NULL;
    limber_gripper *gripper = NULL;
    limber_ranger *laser = NULL;
    limber_code c = limber_limb_connect(limb_name, NULL, CONNECT_MS, &limb);
    if (c != LIMBER_CODE_OK) return failed("connect", c);
    c = limber_gripper_connect(gripper_name, NULL, CONNECT_MS, &gripper);
    if (c != LIMBER_CODE_OK) {
        limber_limb_disconnect(limb);
        return failed("connect", c);
    }
    c = limber_ranger_connect(laser_name, NULL, CONNECT_MS, &laser);
    if (c != LIMBER_CODE_OK) {
        limber_gripper_disconnect(gripper);
        limber_limb_disconnect(limb);
        return failed("connect", c);
    }
    int rc = pick(limb, gripper, laser, 0.38, -0.10);
    if (rc == 2) {
        printf("Target out of reach, terminating\n");
        limber_ticket t;
        wait_limb(limb, "home", limber_limb_home(limb, &t), t);
    } else if (rc == 0) {
        printf("done: block picked up and put down\n");
    }
    limber_ranger_disconnect(laser);
    limber_gripper_disconnect(gripper);
    limber_limb_disconnect(limb);
    return rc;
}
