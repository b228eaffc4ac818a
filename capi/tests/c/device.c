/* device.c: the calls every interface shares (limber_device_*), against the Pioneer driver
 * on the emulator: any device by name, a typed call on a device of another interface, a
 * struct of the wrong size, status names, waiting on two devices with poll(2), an outcome
 * that names the holder, the holder after a refused acquire, the driver's statistics, the
 * library's log through a callback. One line per step, "all device steps ok" at the end;
 * non-zero at the first step that does not do what limber_client.h says. Bounded waits. */
#define _POSIX_C_SOURCE 200809L
#include <limber_client.h>

#include <poll.h>
#include <stdio.h>
#include <string.h>

#define WAIT_MS 5000

static int fail(const char *what, limber_code c) {
    fprintf(stderr, "device: %s: %s: %s\n", what, limber_strerror(c), limber_last_error());
    return 1;
}

static char logged[512];

static void on_log(limber_log_level level, const char *target, const char *message, void *user) {
    (void)target;
    if (level >= LIMBER_LOG_LEVEL_WARN && strstr(message, "layout version") != NULL) {
        snprintf(logged, sizeof logged, "%s", message);
        ++*(int *)user;
    }
}

int main(void) {
    limber_code c;
    /* Status names and "carried out?", from the manifest. */
    printf("status %s %s %s\n", limber_status_name(LIMBER_STATUS_OUT_OF_REACH),
           limber_status_name(LIMBER_STATUS_CLAMPED), limber_status_name(999));
    if (!limber_status_is_carried_out(LIMBER_STATUS_OK) || !limber_status_is_carried_out(LIMBER_STATUS_CLAMPED) ||
        !limber_status_is_carried_out(LIMBER_STATUS_ADJUSTED) || limber_status_is_carried_out(LIMBER_STATUS_LEASED) ||
        limber_status_is_carried_out(999)) {
        fprintf(stderr, "device: limber_status_is_carried_out is wrong\n");
        return 1;
    }

    /* Any device by its name. */
    limber_device *arm = NULL, *grip = NULL, *other = NULL;
    if ((c = limber_device_connect("pioneer/actarray/0", NULL, WAIT_MS, &arm)) != LIMBER_CODE_OK)
        return fail("connect the arm", c);
    if ((c = limber_gripper_connect("pioneer/gripper/1", NULL, WAIT_MS, &grip)) != LIMBER_CODE_OK)
        return fail("connect the gripper", c);
    if ((c = limber_device_connect("pioneer/actarray/0", NULL, WAIT_MS, &other)) != LIMBER_CODE_OK)
        return fail("connect another client", c);
    limber_interface kind = LIMBER_INTERFACE_GRIPPER;
    if ((c = limber_device_interface(arm, &kind)) != LIMBER_CODE_OK) return fail("interface", c);
    printf("name %s interface %d\n", limber_device_name(arm), (int)kind);

    /* A gripper call on the arm, a gripper struct for the arm's state: refused, nothing sent. */
    limber_ticket t;
    c = limber_gripper_open(arm, &t);
    printf("gripper call on the arm: %s: %s\n", limber_strerror(c), limber_last_error());
    if (c != LIMBER_CODE_INCOMPATIBLE) return fail("gripper call on the arm", c);
    limber_gripper_data gd;
    c = limber_device_state(arm, WAIT_MS, &gd, sizeof gd);
    if (c != LIMBER_CODE_INCOMPATIBLE) return fail("a struct of the wrong size", c);
    printf("wrong size: refused\n");
    /* A typed connect of the wrong interface. */
    limber_gripper *not_a_gripper = NULL;
    c = limber_gripper_connect("pioneer/actarray/0", NULL, WAIT_MS, &not_a_gripper);
    printf("gripper connect to the arm: %s: %s\n", limber_strerror(c), limber_last_error());
    if (c != LIMBER_CODE_INCOMPATIBLE || not_a_gripper != NULL) return fail("typed connect", c);

    /* Two devices in one poll(2): the arm's descriptor turns readable with its states. */
    int fds[2] = {-1, -1};
    if ((c = limber_device_fd(arm, &fds[0])) != LIMBER_CODE_OK) return fail("fd", c);
    if ((c = limber_device_fd(grip, &fds[1])) != LIMBER_CODE_OK) return fail("fd", c);
    limber_actarray_data ad;
    if ((c = limber_actarray_state(arm, WAIT_MS, &ad)) != LIMBER_CODE_OK) return fail("state", c);
    if ((c = limber_actarray_move_to(arm, 0, 0.1, &t)) != LIMBER_CODE_OK) return fail("move", c);
    int got_arm = 0;
    for (int i = 0; i < 100 && !got_arm; ++i) {
        struct pollfd p[2] = {{fds[0], POLLIN, 0}, {fds[1], POLLIN, 0}};
        int n = poll(p, 2, WAIT_MS);
        if (n <= 0) {
            fprintf(stderr, "device: poll: nothing within %d ms\n", WAIT_MS);
            return 1;
        }
        for (int k = 0; k < 2; ++k) {
            if (!(p[k].revents & POLLIN)) continue;
            bool fresh = false;
            if ((c = limber_device_refresh(k == 0 ? arm : grip, &fresh)) != LIMBER_CODE_OK) return fail("refresh", c);
            if (k == 0 && fresh) got_arm = 1;
        }
    }
    if (!got_arm) {
        fprintf(stderr, "device: the arm's descriptor never brought a state\n");
        return 1;
    }
    uint32_t status = 0;
    if ((c = limber_device_wait_outcome(arm, t, WAIT_MS, &status)) != LIMBER_CODE_OK) return fail("outcome", c);
    printf("poll: the arm's state came; move %s\n", limber_status_name(status));

    /* An outcome that names the holder; the holder of a refused acquire. */
    uint64_t arm_id = 0;
    if ((c = limber_device_client_id(arm, &arm_id)) != LIMBER_CODE_OK) return fail("client id", c);
    if ((c = limber_device_acquire(arm, "alice", 2000)) != LIMBER_CODE_OK) return fail("acquire", c);
    if ((c = limber_actarray_move_to(other, 1, 0.1, &t)) != LIMBER_CODE_OK) return fail("other's move", c);
    limber_outcome o;
    if ((c = limber_device_outcome(other, t, WAIT_MS, &o)) != LIMBER_CODE_OK) return fail("other's outcome", c);
    printf("other's move: %s by %s (the holder: %s)\n", limber_status_name(o.status), o.other_name,
           o.other_client == arm_id ? "yes" : "no");
    c = limber_device_acquire(other, "bob", 2000);
    limber_lease_holder h;
    limber_last_holder(&h);
    printf("other's acquire: %s; last holder %s (the holder: %s)\n", limber_strerror(c), h.name,
           h.client_id == arm_id ? "yes" : "no");
    if ((c = limber_device_release_lease(arm)) != LIMBER_CODE_OK) return fail("release", c);

    /* The driver's statistics. */
    limber_stats *s = NULL;
    if ((c = limber_stats_open("pioneer", NULL, &s)) != LIMBER_CODE_OK) return fail("stats", c);
    limber_driver_stats ds;
    if ((c = limber_stats_wait(s, WAIT_MS, &ds)) != LIMBER_CODE_OK) return fail("stats wait", c);
    printf("stats: %s cycles %s\n", ds.cycles > 0 ? "some" : "none",
           limber_stats_latest(s, &ds) == LIMBER_CODE_OK ? "latest ok" : "latest failed");
    limber_stats_close(s);

    /* The library's log through a callback: a program of another layout is warned about. */
    int warnings = 0;
    if ((c = limber_set_logger(on_log, &warnings, LIMBER_LOG_LEVEL_WARN)) != LIMBER_CODE_OK) return fail("logger", c);
    limber_device *old = NULL;
    c = limber_device_connect_checked("pioneer/actarray/0", NULL, 0, LIMBER_LAYOUT_VERSION + 1, -1, 0, 0, &old);
    limber_set_logger(NULL, NULL, LIMBER_LOG_LEVEL_OFF);
    printf("log: %d warning(s): %s\n", warnings, logged);
    if (c != LIMBER_CODE_INCOMPATIBLE || warnings != 1) return fail("logger", c);

    limber_device_disconnect(other);
    limber_device_disconnect(grip);
    limber_device_disconnect(arm);
    printf("all device steps ok\n");
    return 0;
}
