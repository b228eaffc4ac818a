/* commands.c: every command and request of the C API once, against the Pioneer driver;
 * prints "<call>: <outcome>" per call (the driver's verdict, or the limber error), so
 * that the test sees each function reach the driver as the command it names. */
#include <limber_client.h>

#include <stdio.h>

#define WAIT_MS 5000

static limber_ticket t;
static uint32_t status;

static void outcome(const char *what, limber_code sent, limber_code (*wait)(void *, limber_ticket, uint64_t, uint32_t *),
                    void *h) {
    if (sent != LIMBER_CODE_OK) {
        printf("%s: error %s\n", what, limber_strerror(sent));
        return;
    }
    limber_code c = wait(h, t, WAIT_MS, &status);
    if (c == LIMBER_CODE_OK)
        printf("%s: %s\n", what, limber_status_text(status));
    else
        printf("%s: error %s\n", what, limber_strerror(c));
}

static void request(const char *what, limber_code c) {
    if (c == LIMBER_CODE_OK)
        printf("%s: ok\n", what);
    else if (c == LIMBER_CODE_REFUSED)
        printf("%s: refused: %s\n", what, limber_status_text(limber_last_refusal()));
    else
        printf("%s: error %s\n", what, limber_strerror(c));
}

static limber_code wait_arm(void *h, limber_ticket tk, uint64_t ms, uint32_t *s) { return limber_actarray_wait_outcome(h, tk, ms, s); }
static limber_code wait_limb(void *h, limber_ticket tk, uint64_t ms, uint32_t *s) { return limber_limb_wait_outcome(h, tk, ms, s); }
static limber_code wait_grip(void *h, limber_ticket tk, uint64_t ms, uint32_t *s) { return limber_gripper_wait_outcome(h, tk, ms, s); }

int main(void) {
    limber_actarray *a = NULL;
    limber_limb *l = NULL;
    limber_gripper *g = NULL;
    if (limber_actarray_connect("pioneer/actarray/0", NULL, WAIT_MS, &a) != LIMBER_CODE_OK ||
        limber_limb_connect("pioneer/limb/0", NULL, WAIT_MS, &l) != LIMBER_CODE_OK ||
        limber_gripper_connect("pioneer/gripper/1", NULL, WAIT_MS, &g) != LIMBER_CODE_OK) {
        fprintf(stderr, "connect: %s\n", limber_last_error());
        return 1;
    }
    double v[3] = {0.1, 0.1, 0.1};
    outcome("actarray move_to", limber_actarray_move_to(a, 0, 0.1, &t), wait_arm, a);
    outcome("actarray move_to_multi", limber_actarray_move_to_multi(a, v, 3, &t), wait_arm, a);
    outcome("actarray move_at_speed", limber_actarray_move_at_speed(a, 0, 0.1, &t), wait_arm, a);
    outcome("actarray move_at_speed_multi", limber_actarray_move_at_speed_multi(a, v, 3, &t), wait_arm, a);
    outcome("actarray set_current", limber_actarray_set_current(a, 0, 0.1, &t), wait_arm, a);
    outcome("actarray set_current_multi", limber_actarray_set_current_multi(a, v, 3, &t), wait_arm, a);
    outcome("actarray home", limber_actarray_home(a, -1, &t), wait_arm, a);
    request("actarray power", limber_actarray_power(a, true, WAIT_MS));
    request("actarray brakes", limber_actarray_brakes(a, true, WAIT_MS));
    request("actarray set_speed_config", limber_actarray_set_speed_config(a, 0, 1.0, WAIT_MS));
    request("actarray set_accel_config", limber_actarray_set_accel_config(a, 0, 1.0, WAIT_MS));
    limber_actarray_geom ag;
    request("actarray geometry", limber_actarray_geometry(a, WAIT_MS, &ag));

    limber_vec3 p = {0.38, 0.0, 0.22}, down = {0, 0, -1}, across = {1, 0, 0};
    outcome("limb set_pose", limber_limb_set_pose(l, p, down, across, &t), wait_limb, l);
    outcome("limb set_position", limber_limb_set_position(l, p, &t), wait_limb, l);
    outcome("limb vec_move", limber_limb_vec_move(l, down, 0.01, &t), wait_limb, l);
    outcome("limb stop", limber_limb_stop(l, &t), wait_limb, l);
    outcome("limb home", limber_limb_home(l, &t), wait_limb, l);
    request("limb power", limber_limb_power(l, true, WAIT_MS));
    request("limb brakes", limber_limb_brakes(l, true, WAIT_MS));
    request("limb set_speed", limber_limb_set_speed(l, 0.1, WAIT_MS));
    limber_limb_geom lg;
    request("limb geometry", limber_limb_geometry(l, WAIT_MS, &lg));
    /* The README's pose: reachable with its orientation adjusted; 5 m away: out of reach. */
    limber_limb_reach lr;
    limber_vec3 rp = {0.38, 0.1, 0.22}, ra = {0, 0, -1}, ro = {0.94, 0.34, 0}, far = {5, 0, 0};
    request("limb can_reach", limber_limb_can_reach(l, rp, ra, ro, WAIT_MS, &lr));
    printf("limb can_reach adjusted: %s\n", lr.adjusted && lr.orientation_adjustment > 0 ? "yes" : "no");
    request("limb can_reach far", limber_limb_can_reach(l, far, ra, ro, WAIT_MS, &lr));

    outcome("gripper open", limber_gripper_open(g, &t), wait_grip, g);
    outcome("gripper close", limber_gripper_close(g, &t), wait_grip, g);
    outcome("gripper stop", limber_gripper_stop(g, &t), wait_grip, g);
    outcome("gripper store", limber_gripper_store(g, &t), wait_grip, g);
    outcome("gripper retrieve", limber_gripper_retrieve(g, &t), wait_grip, g);
    limber_gripper_geom gg;
    request("gripper geometry", limber_gripper_geometry(g, WAIT_MS, &gg));

    limber_gripper_disconnect(g);
    limber_limb_disconnect(l);
    limber_actarray_disconnect(a);
    return 0;
}
