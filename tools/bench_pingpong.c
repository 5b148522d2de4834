/* bench_pingpong: the time a cache line takes to go from one core to
 * another and back, as two threads hand a counter to each other: what
 * every exchange between the OpenMP threads of a step costs on this
 * machine at this moment (a virtual machine's two cores may sit on one
 * die or on two, as its host places them; benchmarks/bench-two-threads.sh).
 * usage: bench-pingpong [ROUNDS]   (prints the mean round trip, ns) */
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static _Atomic long turn; /* odd: the other thread's, even: the first's */
static long rounds = 1000000;

static void *answer(void *arg) {
  (void)arg;
  for (long i = 0; i < rounds; i++) {
    while (atomic_load_explicit(&turn, memory_order_acquire) != 2 * i + 1) {
    }
    atomic_store_explicit(&turn, 2 * i + 2, memory_order_release);
  }
  return NULL;
}

int main(int argc, char **argv) {
  if (argc > 1) rounds = atol(argv[1]);
  if (rounds < 1) {
    fprintf(stderr, "usage: bench-pingpong [ROUNDS >= 1]\n");
    return 1;
  }
  pthread_t other;
  if (pthread_create(&other, NULL, answer, NULL) != 0) {
    fprintf(stderr, "bench-pingpong: cannot start a thread\n");
    return 1;
  }
  struct timespec a, b;
  clock_gettime(CLOCK_MONOTONIC, &a);
  for (long i = 0; i < rounds; i++) {
    atomic_store_explicit(&turn, 2 * i + 1, memory_order_release);
    while (atomic_load_explicit(&turn, memory_order_acquire) != 2 * i + 2) {
    }
  }
  clock_gettime(CLOCK_MONOTONIC, &b);
  pthread_join(other, NULL);
  const double ns = (b.tv_sec - a.tv_sec) * 1e9 + (b.tv_nsec - a.tv_nsec);
  printf("%.0f\n", ns / rounds);
  return 0;
}
