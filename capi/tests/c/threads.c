/* threads.c: the thread-safety the header documents. Two threads each open handles of
 * their own and read states at the same time; a handle opened by the main thread is then
 * used by another thread (one at a time). Prints "threads ok". */
#include <limber_client.h>

#include <pthread.h>
#include <stdio.h>

static void *read_arm(void *arg) {
    (void)arg;
    limber_actarray *arm = NULL;
    if (limber_actarray_connect("pioneer/actarray/0", NULL, 5000, &arm) != LIMBER_CODE_OK) return (void *)1;
    limber_actarray_data d;
    for (int i = 0; i < 20; i++)
        if (limber_actarray_wait_state(arm, 2000, &d) != LIMBER_CODE_OK) return (void *)1;
    limber_actarray_disconnect(arm);
    return NULL;
}

static void *read_limb(void *arg) {
    (void)arg;
    limber_limb *limb = NULL;
    if (limber_limb_connect("pioneer/limb/0", NULL, 5000, &limb) != LIMBER_CODE_OK) return (void *)1;
    limber_limb_data d;
    for (int i = 0; i < 20; i++)
        if (limber_limb_wait_state(limb, 2000, &d) != LIMBER_CODE_OK) return (void *)1;
    limber_limb_disconnect(limb);
    return NULL;
}

static void *use_gripper(void *arg) {
    limber_gripper *g = arg;
    limber_gripper_geom geom;
    limber_gripper_data d;
    if (limber_gripper_geometry(g, 2000, &geom) != LIMBER_CODE_OK) return (void *)1;
    if (limber_gripper_wait_state(g, 2000, &d) != LIMBER_CODE_OK) return (void *)1;
    return NULL;
}

int main(void) {
    pthread_t a, b, c;
    void *ra, *rb, *rc;
    pthread_create(&a, NULL, read_arm, NULL);
    pthread_create(&b, NULL, read_limb, NULL);
    pthread_join(a, &ra);
    pthread_join(b, &rb);
    limber_gripper *g = NULL;
    if (limber_gripper_connect("pioneer/gripper/1", NULL, 5000, &g) != LIMBER_CODE_OK) return 1;
    limber_gripper_data d;
    if (limber_gripper_state(g, 2000, &d) != LIMBER_CODE_OK) return 1;
    pthread_create(&c, NULL, use_gripper, g);
    pthread_join(c, &rc);
    if (limber_gripper_state(g, 2000, &d) != LIMBER_CODE_OK) return 1;
    limber_gripper_disconnect(g);
    if (ra != NULL || rb != NULL || rc != NULL) {
        fprintf(stderr, "a thread failed: %s\n", limber_last_error());
        return 1;
    }
    printf("threads ok\n");
    return 0;
}
