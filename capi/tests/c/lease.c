/* lease.c: control leases and preemption from C, two handles (two clients) of one program
 * on the arm. Prints one line per step and "all lease steps ok" at the end; exits non-zero
 * at the first step that does not do what limber_client.h says. Every wait is bounded. */
#define _POSIX_C_SOURCE 200809L
#include <limber_client.h>

#include <stdio.h>
#include <string.h>
#include <time.h>

#define WAIT_MS 5000
/* How long a step may wait for the driver (a bound, not a measurement). */
#define STEP_LIMIT_S 20.0

static int fail(const char *what, limber_code c) {
    fprintf(stderr, "lease: %s: %s: %s (refusal %s)\n", what, limber_strerror(c), limber_last_error(),
            limber_status_text(limber_last_refusal()));
    return 1;
}

static double now_s(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

/* Sends move_to(joint, position) from `h` and returns its outcome's status in *status. */
static limber_code move_and_wait(limber_actarray *h, unsigned joint, double position, uint32_t *status) {
    limber_ticket t;
    limber_code c = limber_actarray_move_to(h, joint, position, &t);
    if (c != LIMBER_CODE_OK) return c;
    return limber_actarray_wait_outcome(h, t, WAIT_MS, status);
}

int main(void) {
    limber_actarray *alice = NULL, *bob = NULL;
    limber_limb *limb = NULL;
    limber_code c;
    if ((c = limber_actarray_connect("pioneer/actarray/0", NULL, WAIT_MS, &alice)) != LIMBER_CODE_OK)
        return fail("connect alice", c);
    if ((c = limber_actarray_connect("pioneer/actarray/0", NULL, WAIT_MS, &bob)) != LIMBER_CODE_OK)
        return fail("connect bob", c);
    if ((c = limber_limb_connect("pioneer/limb/0", NULL, WAIT_MS, &limb)) != LIMBER_CODE_OK)
        return fail("connect limb", c);
    uint64_t alice_id = 0, bob_id = 0;
    if ((c = limber_actarray_client_id(alice, &alice_id)) != LIMBER_CODE_OK) return fail("client_id", c);
    if ((c = limber_actarray_client_id(bob, &bob_id)) != LIMBER_CODE_OK) return fail("client_id", c);
    if (alice_id == 0 || alice_id == bob_id) {
        fprintf(stderr, "lease: client ids %llu and %llu\n", (unsigned long long)alice_id,
                (unsigned long long)bob_id);
        return 1;
    }

    /* Names: empty or too long is an error code with a message; nothing is sent. */
    if ((c = limber_actarray_acquire(alice, "", 1000)) != LIMBER_CODE_INVALID_VALUE) return fail("empty name", c);
    printf("empty name: %s: %s\n", limber_strerror(c), limber_last_error());
    if ((c = limber_actarray_acquire(alice, "a-name-that-is-longer-than-31-bytes", 1000)) !=
        LIMBER_CODE_INVALID_VALUE)
        return fail("long name", c);
    /* A heartbeat the driver does not accept. */
    if ((c = limber_actarray_acquire(alice, "alice", 0)) != LIMBER_CODE_REFUSED ||
        limber_last_refusal() != LIMBER_STATUS_INVALID_ARGUMENT)
        return fail("heartbeat 0", c);
    limber_lease_holder who;
    if ((c = limber_actarray_holder(bob, &who)) != LIMBER_CODE_OK || who.client_id != 0)
        return fail("nobody holds the arm", c);

    /* Alice takes the arm: Bob is refused, by name. */
    if ((c = limber_actarray_acquire(alice, "alice", 5000)) != LIMBER_CODE_OK) return fail("acquire", c);
    if ((c = limber_actarray_holder(bob, &who)) != LIMBER_CODE_OK) return fail("holder", c);
    if (who.client_id != alice_id || strcmp(who.name, "alice") != 0 || who.heartbeat_ms != 5000) {
        fprintf(stderr, "lease: holder %llu %s %llu ms\n", (unsigned long long)who.client_id, who.name,
                (unsigned long long)who.heartbeat_ms);
        return 1;
    }
    printf("holder: %s\n", who.name);
    uint32_t status = LIMBER_STATUS_OK;
    if ((c = move_and_wait(bob, 2, 0.3, &status)) != LIMBER_CODE_OK) return fail("bob's move", c);
    if (status != LIMBER_STATUS_LEASED || limber_last_refusal() != LIMBER_STATUS_LEASED ||
        strstr(limber_last_error(), "alice") == NULL) {
        fprintf(stderr, "lease: bob's move while alice holds the arm: %s (%s)\n", limber_status_text(status),
                limber_last_error());
        return 1;
    }
    printf("bob's move: %s: %s\n", limber_status_text(status), limber_last_error());
    if ((c = limber_actarray_acquire(bob, "bob", 2000)) != LIMBER_CODE_REFUSED ||
        limber_last_refusal() != LIMBER_STATUS_LEASED || strstr(limber_last_error(), "alice") == NULL)
        return fail("bob's acquire", c);
    printf("bob's acquire: %s: %s\n", limber_strerror(c), limber_last_error());
    if ((c = limber_actarray_power(bob, true, WAIT_MS)) != LIMBER_CODE_REFUSED ||
        limber_last_refusal() != LIMBER_STATUS_LEASED)
        return fail("bob's power request", c);
    /* A lease on the arm's joints holds the arm: its limb names the same holder. */
    limber_lease_holder limb_holder;
    if ((c = limber_limb_holder(limb, &limb_holder)) != LIMBER_CODE_OK || limb_holder.client_id != alice_id ||
        strcmp(limb_holder.name, "alice") != 0)
        return fail("limb holder while alice holds the arm", c);
    printf("limb held with the arm: %s\n", limb_holder.name);
    /* The holder commands; renews. */
    if ((c = move_and_wait(alice, 2, 0.3, &status)) != LIMBER_CODE_OK || status != LIMBER_STATUS_OK)
        return fail("alice's move", c);
    if ((c = limber_actarray_renew(alice)) != LIMBER_CODE_OK) return fail("renew", c);
    bool renewed = false; /* whether a third of the heartbeat has passed: not asserted */
    if ((c = limber_actarray_keep_lease(alice, &renewed)) != LIMBER_CODE_OK) return fail("keep_lease", c);

    /* Alice gives the arm back: Bob's command is carried out. */
    if ((c = limber_actarray_release_lease(alice)) != LIMBER_CODE_OK) return fail("release_lease", c);
    if ((c = limber_actarray_release_lease(alice)) != LIMBER_CODE_OK) return fail("release_lease again", c);
    if ((c = limber_actarray_holder(bob, &who)) != LIMBER_CODE_OK || who.client_id != 0)
        return fail("holder after release", c);
    if ((c = move_and_wait(bob, 2, 0.0, &status)) != LIMBER_CODE_OK || status != LIMBER_STATUS_OK)
        return fail("bob's move after release", c);
    printf("bob's move after release: %s\n", limber_status_text(status));

    /* The limb's lease, under this program's name (NULL). */
    if ((c = limber_limb_acquire(limb, NULL, 2000)) != LIMBER_CODE_OK) return fail("limb acquire", c);
    if ((c = limber_limb_holder(limb, &limb_holder)) != LIMBER_CODE_OK) return fail("limb holder", c);
    printf("limb holder: %s\n", limb_holder.name);
    if ((c = limber_limb_release_lease(limb)) != LIMBER_CODE_OK) return fail("limb release", c);

    /* The gripper's lease. */
    limber_gripper *grip = NULL;
    if ((c = limber_gripper_connect("pioneer/gripper/1", NULL, WAIT_MS, &grip)) != LIMBER_CODE_OK)
        return fail("connect gripper", c);
    if ((c = limber_gripper_acquire(grip, "grip", 2000)) != LIMBER_CODE_OK) return fail("gripper acquire", c);
    limber_lease_holder grip_holder;
    if ((c = limber_gripper_holder(grip, &grip_holder)) != LIMBER_CODE_OK || strcmp(grip_holder.name, "grip") != 0)
        return fail("gripper holder", c);
    if ((c = limber_gripper_renew(grip)) != LIMBER_CODE_OK) return fail("gripper renew", c);
    if ((c = limber_gripper_release_lease(grip)) != LIMBER_CODE_OK) return fail("gripper release", c);
    if ((c = limber_gripper_holder(grip, &grip_holder)) != LIMBER_CODE_OK || grip_holder.client_id != 0)
        return fail("gripper holder after release", c);
    limber_gripper_disconnect(grip);
    printf("gripper lease ok\n");

    /* NULL where a pointer is required. */
    limber_ticket none = {0, 0};
    if ((c = limber_actarray_acquire(NULL, "alice", 1000)) != LIMBER_CODE_NULL_ARGUMENT) return fail("NULL handle", c);
    if ((c = limber_actarray_holder(bob, NULL)) != LIMBER_CODE_NULL_ARGUMENT) return fail("NULL holder", c);
    if ((c = limber_limb_preempted(limb, none, NULL, NULL)) != LIMBER_CODE_NULL_ARGUMENT)
        return fail("NULL preempted", c);
    if ((c = limber_actarray_client_id(bob, NULL)) != LIMBER_CODE_NULL_ARGUMENT) return fail("NULL id", c);

    /* Preemption: Alice turns joint 0 slowly; Bob stops it. */
    limber_ticket slow;
    if ((c = limber_actarray_move_at_speed(alice, 0, 0.2, &slow)) != LIMBER_CODE_OK) return fail("slow move", c);
    if ((c = limber_actarray_wait_outcome(alice, slow, WAIT_MS, &status)) != LIMBER_CODE_OK ||
        status != LIMBER_STATUS_OK)
        return fail("slow move's outcome", c);
    bool preempted = true;
    uint64_t by = 1;
    if ((c = limber_actarray_preempted(alice, slow, &preempted, &by)) != LIMBER_CODE_OK || preempted || by != 0)
        return fail("preempted before bob's command", c);
    limber_ticket stop;
    if ((c = limber_actarray_move_at_speed(bob, 0, 0.0, &stop)) != LIMBER_CODE_OK) return fail("bob's stop", c);
    if ((c = limber_actarray_wait_outcome(bob, stop, WAIT_MS, &status)) != LIMBER_CODE_OK ||
        status != LIMBER_STATUS_OK)
        return fail("bob's stop's outcome", c);
    for (double end = now_s() + STEP_LIMIT_S; !preempted && now_s() < end;) {
        if ((c = limber_actarray_wait_state(alice, WAIT_MS, NULL)) != LIMBER_CODE_OK) return fail("wait_state", c);
        if ((c = limber_actarray_preempted(alice, slow, &preempted, &by)) != LIMBER_CODE_OK) return fail("preempted", c);
    }
    if (!preempted || by != bob_id) {
        fprintf(stderr, "lease: alice's slow move preempted %d by %llu (bob is %llu)\n", preempted,
                (unsigned long long)by, (unsigned long long)bob_id);
        return 1;
    }
    printf("alice's slow move preempted by bob\n");

    /* The deadman: Alice turns joint 0, takes the arm with a short heartbeat and stops
     * renewing; the driver frees the lease and stops the joint. (The move goes first, so
     * that it is carried out before the lease can end, however slow this machine.) */
    if ((c = limber_actarray_move_at_speed(alice, 0, 0.2, &slow)) != LIMBER_CODE_OK) return fail("slow move 2", c);
    if ((c = limber_actarray_wait_outcome(alice, slow, WAIT_MS, &status)) != LIMBER_CODE_OK ||
        status != LIMBER_STATUS_OK)
        return fail("slow move 2's outcome", c);
    if ((c = limber_actarray_acquire(alice, "alice", 100)) != LIMBER_CODE_OK) return fail("acquire 100 ms", c);
    who.client_id = alice_id;
    for (double end = now_s() + STEP_LIMIT_S; who.client_id != 0 && now_s() < end;) {
        if ((c = limber_actarray_wait_state(bob, WAIT_MS, NULL)) != LIMBER_CODE_OK) return fail("wait_state", c);
        if ((c = limber_actarray_holder(bob, &who)) != LIMBER_CODE_OK) return fail("holder", c);
    }
    if (who.client_id != 0) {
        fprintf(stderr, "lease: alice still holds the arm after missing her heartbeat\n");
        return 1;
    }
    limber_actarray_data d;
    int moving = 1;
    for (double end = now_s() + STEP_LIMIT_S; moving && now_s() < end;) {
        if ((c = limber_actarray_wait_state(bob, WAIT_MS, &d)) != LIMBER_CODE_OK) return fail("wait_state", c);
        moving = (d.actuators[0].state & LIMBER_ACTSTATE_MOVING) != 0;
    }
    if (moving) {
        fprintf(stderr, "lease: joint 0 still moves after the deadman\n");
        return 1;
    }
    if ((c = limber_actarray_renew(alice)) != LIMBER_CODE_LEASE_LOST) return fail("renew after the deadman", c);
    printf("alice's renew after the deadman: %s\n", limber_strerror(c));

    limber_limb_disconnect(limb);
    limber_actarray_disconnect(bob);
    limber_actarray_disconnect(alice);
    printf("all lease steps ok\n");
    return 0;
}
