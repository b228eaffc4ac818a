/* joints.c: written from limber_client.h's documentation alone. Connects to the arm,
 * reads its joints (borrowed in place, then copied), moves one joint and waits until the
 * arm reports it there. Prints "moved joint J from A to B"; exits non-zero on failure. */
#include <limber_client.h>

#include <math.h>
#include <stdio.h>

static int fail(const char *what, limber_code c) {
    fprintf(stderr, "joints: %s: %s: %s\n", what, limber_strerror(c), limber_last_error());
    return 1;
}

int main(void) {
    limber_actarray *arm = NULL;
    limber_code c = limber_actarray_connect("pioneer/actarray/0", NULL, 5000, &arm);
    if (c != LIMBER_CODE_OK) return fail("connect", c);

    /* Zero-copy: the state in shared memory, until released. */
    const limber_actarray_data *in_place = NULL;
    if ((c = limber_actarray_borrow(arm, 2000, &in_place)) != LIMBER_CODE_OK) return fail("borrow", c);
    unsigned count = in_place->actuators_count;
    printf("%u joints:", count);
    for (unsigned j = 0; j < count; j++) printf(" %.3f", in_place->actuators[j].position);
    printf("\n");
    limber_actarray_data copy;
    if (limber_actarray_state(arm, 0, &copy) != LIMBER_CODE_BORROWED) return fail("state while borrowed", c);
    if ((c = limber_actarray_release(arm)) != LIMBER_CODE_OK) return fail("release", c);

    limber_actarray_geom geom;
    if ((c = limber_actarray_geometry(arm, 2000, &geom)) != LIMBER_CODE_OK) return fail("geometry", c);
    const unsigned joint = 1;
    double from = 0.0, target = geom.actuators[joint].home + 0.3;
    if (target > geom.actuators[joint].max) target = geom.actuators[joint].home - 0.3;
    if ((c = limber_actarray_state(arm, 2000, &copy)) != LIMBER_CODE_OK) return fail("state", c);
    from = copy.actuators[joint].position;

    limber_ticket ticket;
    if ((c = limber_actarray_move_to(arm, joint, target, &ticket)) != LIMBER_CODE_OK) return fail("move_to", c);
    uint32_t status;
    if ((c = limber_actarray_wait_outcome(arm, ticket, 5000, &status)) != LIMBER_CODE_OK)
        return fail("wait_outcome", c);
    if (status != LIMBER_STATUS_OK) {
        fprintf(stderr, "joints: refused: %s\n", limber_status_text(status));
        return 1;
    }
    for (int i = 0; i < 300; i++) {
        if ((c = limber_actarray_wait_state(arm, 2000, &copy)) != LIMBER_CODE_OK) return fail("wait_state", c);
        if (fabs(copy.actuators[joint].position - target) < 0.02 &&
            !(copy.actuators[joint].state & LIMBER_ACTSTATE_MOVING))
            break;
    }
    limber_liveness live;
    if ((c = limber_actarray_liveness(arm, 1000, &live)) != LIMBER_CODE_OK) return fail("liveness", c);
    printf("moved joint %u from %.3f to %.3f (target %.3f); driver %s\n", joint, from,
           copy.actuators[joint].position, target, live == LIMBER_LIVENESS_ALIVE ? "alive" : "not alive");
    limber_actarray_disconnect(arm);
    return fabs(copy.actuators[joint].position - target) < 0.02 && live == LIMBER_LIVENESS_ALIVE ? 0 : 1;
}
