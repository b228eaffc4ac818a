/* errors.c: the error paths of the C API, each checked; prints "ok: ..." per check and
 * "all error paths ok" at the end (exit 0), or the first mismatch (exit 1). A driver
 * offering pioneer/... runs in LIMBER_DOMAIN. */
#include <limber_client.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

static int check(const char *what, limber_code got, limber_code want, const char *in_detail) {
    const char *detail = limber_last_error();
    if (got != want || (in_detail != NULL && strstr(detail, in_detail) == NULL)) {
        fprintf(stderr, "FAIL %s: got %d (%s), want %d; detail: %s\n", what, got,
                limber_strerror(got), want, detail);
        return 1;
    }
    printf("ok: %s: %s: %s\n", what, limber_strerror(got), detail);
    return 0;
}

int main(void) {
    int bad = 0;
    limber_actarray *arm = NULL;
    limber_actarray_data d;
    limber_ticket t;

    bad |= check("unknown device", limber_actarray_connect("pioneer/actarray/7", NULL, 100, &arm),
                 LIMBER_CODE_NO_DRIVER, "no driver offers pioneer/actarray/7");
    bad |= arm != NULL;
    bad |= check("NULL device", limber_actarray_connect(NULL, NULL, 0, &arm), LIMBER_CODE_NULL_ARGUMENT,
                 "device is NULL");
    bad |= check("NULL out", limber_actarray_connect("pioneer/actarray/0", NULL, 0, NULL),
                 LIMBER_CODE_NULL_ARGUMENT, "out is NULL");
    bad |= check("bad UTF-8", limber_actarray_connect("pioneer/\xff/0", NULL, 0, &arm), LIMBER_CODE_BAD_UTF8,
                 "not valid UTF-8");
    bad |= check("bad device name", limber_actarray_connect("nonsense", NULL, 0, &arm), LIMBER_CODE_BAD_NAME,
                 "robot/interface/index");
    bad |= check("bad domain", limber_actarray_connect("pioneer/actarray/0", "no spaces!", 0, &arm),
                 LIMBER_CODE_BAD_NAME, "invalid domain");
    bad |= check("another interface", limber_actarray_connect("pioneer/limb/0", NULL, 0, &arm),
                 LIMBER_CODE_INCOMPATIBLE, "not an actarray");
    bad |= check("NULL handle", limber_actarray_state(NULL, 0, &d), LIMBER_CODE_NULL_ARGUMENT, "handle is NULL");
    bad |= check("NULL limb handle", limber_limb_home(NULL, &t), LIMBER_CODE_NULL_ARGUMENT, NULL);
    bad |= check("NULL gripper handle", limber_gripper_close(NULL, NULL), LIMBER_CODE_NULL_ARGUMENT, NULL);
    limber_actarray_disconnect(NULL);
    limber_limb_disconnect(NULL);
    limber_gripper_disconnect(NULL);

    bad |= check("connect", limber_actarray_connect("pioneer/actarray/0", NULL, 5000, &arm), LIMBER_CODE_OK, NULL);
    if (arm == NULL) return 1;
    bad |= check("NaN position", limber_actarray_move_to(arm, 0, NAN, &t), LIMBER_CODE_INVALID_VALUE, "invalid");
    bad |= check("joint 99", limber_actarray_move_to(arm, 99, 0.1, &t), LIMBER_CODE_INVALID_VALUE, NULL);
    bad |= check("NULL values", limber_actarray_move_to_multi(arm, NULL, 3, &t), LIMBER_CODE_NULL_ARGUMENT, NULL);
    bad |= check("NULL status", limber_actarray_wait_outcome(arm, t, 0, NULL), LIMBER_CODE_NULL_ARGUMENT, NULL);
    bad |= check("NULL geometry", limber_actarray_geometry(arm, 1000, NULL), LIMBER_CODE_NULL_ARGUMENT, NULL);
    const limber_actarray_data *p = NULL;
    bad |= check("borrow", limber_actarray_borrow(arm, 2000, &p), LIMBER_CODE_OK, NULL);
    bad |= p == NULL;
    bad |= check("state while borrowed", limber_actarray_state(arm, 0, &d), LIMBER_CODE_BORROWED, "release it");
    bad |= check("borrow twice", limber_actarray_borrow(arm, 0, &p), LIMBER_CODE_BORROWED, NULL);
    bad |= check("release", limber_actarray_release(arm), LIMBER_CODE_OK, NULL);
    bad |= check("state after release", limber_actarray_state(arm, 0, &d), LIMBER_CODE_OK, NULL);
    bad |= check("brakes on an arm without", limber_actarray_brakes(arm, true, 2000), LIMBER_CODE_REFUSED,
                 "unsupported");
    if (limber_last_refusal() != LIMBER_STATUS_UNSUPPORTED) {
        fprintf(stderr, "FAIL refusal: %u\n", limber_last_refusal());
        bad = 1;
    }
    limber_ticket never = {1000000, 1};
    uint32_t status;
    bad |= check("outcome of a command never sent", limber_actarray_wait_outcome(arm, never, 50, &status),
                 LIMBER_CODE_TIMEOUT, "nothing within");
    limber_actarray_disconnect(arm);

    size_t count = 0;
    limber_device_info devices[16];
    bad |= check("list devices", limber_list_devices(NULL, devices, 16, &count), LIMBER_CODE_OK, NULL);
    bad |= check("count only", limber_list_devices(NULL, NULL, 0, &count), LIMBER_CODE_OK, NULL);
    bad |= check("NULL list", limber_list_devices(NULL, NULL, 4, &count), LIMBER_CODE_NULL_ARGUMENT, NULL);
    int found = 0;
    for (size_t i = 0; i < count && i < 16; i++)
        found |= strcmp(devices[i].name, "pioneer/limb/0") == 0 && devices[i].alive &&
                 devices[i].interface == LIMBER_INTERFACE_LIMB;
    if (!found) {
        fprintf(stderr, "FAIL: pioneer/limb/0 not listed alive among %zu devices\n", count);
        bad = 1;
    }
    if (strcmp(limber_strerror(999), "unknown limber code") != 0) bad = 1;
    if (strcmp(limber_strerror(LIMBER_CODE_OK), "ok") != 0) bad = 1;
    if (strcmp(limber_status_text(999), "unknown status") != 0) bad = 1;
    if (limber_layout_version() != LIMBER_LAYOUT_VERSION) bad = 1;
    if (!bad) printf("all error paths ok (%zu devices)\n", count);
    return bad;
}
