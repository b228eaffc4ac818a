/* lang_client.c: the C client of `limber bench`'s `lang` scenario (compiled by the bench
 * against liblimber). Usage: lang_client WARMUP COUNT OUT SETTLE_NS. Connects to
 * bench/actarray/0 in $LIMBER_DOMAIN and, WARMUP + COUNT times each, times (CLOCK_MONOTONIC,
 * ns) reading the latest state (limber_actarray_state, a copy), SETTLE_NS after the previous
 * round trip ended (spinning on the clock; the bench's SETTLE_NS says why), and a command's round trip
 * (limber_actarray_move_to, then limber_actarray_wait_outcome); writes the samples after the
 * warm-up to OUT, one a line: "state NS" or "rtt NS". Exits 1 with the reason on stderr. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include <limber_client.h>

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static uint64_t now_ns(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (uint64_t)t.tv_sec * 1000000000u + (uint64_t)t.tv_nsec;
}

static int fail(const char *what, limber_code c) {
    fprintf(stderr, "lang_client: %s: %s: %s\n", what, limber_strerror(c), limber_last_error());
    return 1;
}

int main(int argc, char **argv) {
    if (argc != 5) {
        fprintf(stderr, "usage: lang_client WARMUP COUNT OUT SETTLE_NS\n");
        return 2;
    }
    long warm = atol(argv[1]), count = atol(argv[2]);
    uint64_t settle = strtoull(argv[4], NULL, 10), settled = 0;
    FILE *out = fopen(argv[3], "w");
    if (!out) {
        perror(argv[3]);
        return 1;
    }
    limber_actarray *arm = NULL;
    limber_code c = limber_actarray_connect("bench/actarray/0", NULL, 15000, &arm);
    if (c != LIMBER_CODE_OK) return fail("connect", c);
    limber_actarray_data d;
    if ((c = limber_actarray_state(arm, 5000, &d)) != LIMBER_CODE_OK) return fail("first state", c);
    for (long i = 1; i <= warm + count; i++) {
        while (now_ns() < settled) {
        }
        uint64_t t0 = now_ns();
        c = limber_actarray_state(arm, 0, &d);
        uint64_t t1 = now_ns();
        if (c != LIMBER_CODE_OK) return fail("state", c);
        limber_ticket ticket;
        uint32_t status = LIMBER_STATUS_OK;
        uint64_t t2 = now_ns();
        if ((c = limber_actarray_move_to(arm, 0, i % 2 ? -0.25 : 0.25, &ticket)) != LIMBER_CODE_OK)
            return fail("move_to", c);
        if ((c = limber_actarray_wait_outcome(arm, ticket, 2000, &status)) != LIMBER_CODE_OK)
            return fail("wait_outcome", c);
        uint64_t t3 = now_ns();
        settled = t3 + settle;
        if (status != LIMBER_STATUS_OK) {
            fprintf(stderr, "lang_client: refused: %s\n", limber_status_text(status));
            return 1;
        }
        if (i > warm) fprintf(out, "state %llu\nrtt %llu\n", (unsigned long long)(t1 - t0),
                              (unsigned long long)(t3 - t2));
    }
    limber_actarray_disconnect(arm);
    return fclose(out) == 0 ? 0 : 1;
}
