/* fpm_scotch: libscotch through a table filled on first use, and a graph
 * partitioned by it. */
#include "fpm_scotch.h"

#include <stdbool.h>
#include <stdlib.h>

/* scotch.h uses FILE and the fixed-width integers without including
 * their headers. */
#include <stdint.h>
#include <stdio.h>
#include <scotch.h>

#include "pm_dl.h"

#ifndef PM_SCOTCH_SONAME
#error "PM_SCOTCH_SONAME: the build names the Scotch library (CMakeLists.txt)"
#endif

/* X(name): every function of Scotch the program uses. */
#define FPM_SCOTCH_API(X)                                                      \
  X(SCOTCH_graphBuild)                                                         \
  X(SCOTCH_graphExit)                                                          \
  X(SCOTCH_graphInit)                                                          \
  X(SCOTCH_graphPart)                                                          \
  X(SCOTCH_numSizeof)                                                          \
  X(SCOTCH_randomReset)                                                        \
  X(SCOTCH_randomSeed)                                                         \
  X(SCOTCH_stratExit)                                                          \
  X(SCOTCH_stratGraphMapBuild)                                                 \
  X(SCOTCH_stratInit)

PM_DL_TABLE(FPM_SCOTCH_API, fpm_scotch_table);
static fpm_scotch_table api;

#define PM_DL_TYPE fpm_scotch_table
static const pm_dl_entry entries[] = {FPM_SCOTCH_API(PM_DL_ENTRY)};

static pm_err load(void) {
  static pm_dl_library lib = {
      .what = "Scotch",
      .soname = PM_SCOTCH_SONAME,
      .built = "scotch.h of Scotch 7 with " SCOTCH_NUMSTRING " integers",
      .entries = entries,
      .n_entries = sizeof entries / sizeof entries[0],
      .table = &api,
  };
  PM_CALL(pm_dl_load(&lib, "the partition of an FPM run across ranks"));
  PM_CHECK(api.SCOTCH_numSizeof() == (int)sizeof(SCOTCH_Num),
           PM_ERR_UNSUPPORTED,
           "Scotch library %s has %d-byte integers, its header %zu: another "
           "Scotch than the one pointmech was built with",
           PM_SCOTCH_SONAME, api.SCOTCH_numSizeof(), sizeof(SCOTCH_Num));
  return PM_SUCCESS;
}

pm_err fpm_scotch_part(long n, const long *ptr, const long *adj,
                       const long *weight, int parts, int *part) {
  pm_err ret = PM_SUCCESS;
  SCOTCH_Num *vert = NULL, *edge = NULL, *velo = NULL, *to = NULL;
  SCOTCH_Graph graph;
  SCOTCH_Strat strat;
  bool graph_made = false, strat_made = false;
  PM_CALL(load());
  PM_CHECK(ptr[n] <= SCOTCH_NUMMAX && n <= SCOTCH_NUMMAX, PM_ERR_UNSUPPORTED,
           "a graph of %ld vertices and %ld edge ends is past Scotch's "
           "integers (at most %ld)",
           n, ptr[n], (long)SCOTCH_NUMMAX);
  /* Scotch's threads would take turns in an order that varies from run to
   * run, and so would its parts; on one it gives the same every time. */
  setenv("SCOTCH_PTHREAD_NUMBER", "1", 1);
  PM_TRY(PM_ALLOC(vert, n + 1, "partition graph"));
  PM_TRY(PM_ALLOC(edge, ptr[n] + 1, "partition graph"));
  PM_TRY(PM_ALLOC(velo, n + 1, "partition graph"));
  PM_TRY(PM_ALLOC(to, n + 1, "partition"));
  for (long i = 0; i <= n; i++) vert[i] = (SCOTCH_Num)ptr[i];
  for (long e = 0; e < ptr[n]; e++) edge[e] = (SCOTCH_Num)adj[e];
  for (long i = 0; i < n; i++) velo[i] = (SCOTCH_Num)weight[i];
  PM_ENSURE(api.SCOTCH_graphInit(&graph) == 0, PM_ERR_INTERNAL,
            "SCOTCH_graphInit failed");
  graph_made = true;
  PM_ENSURE(api.SCOTCH_graphBuild(&graph, 0, (SCOTCH_Num)n, vert, vert + 1,
                                  velo, NULL, (SCOTCH_Num)ptr[n], edge,
                                  NULL) == 0,
            PM_ERR_INTERNAL, "SCOTCH_graphBuild failed (%ld vertices)", n);
  PM_ENSURE(api.SCOTCH_stratInit(&strat) == 0, PM_ERR_INTERNAL,
            "SCOTCH_stratInit failed");
  strat_made = true;
  /* Scotch's default strategy, parts equal to 1%: PT-Scotch's as PETSc
   * called it before (MatPartitioning's defaults). */
  PM_ENSURE(api.SCOTCH_stratGraphMapBuild(&strat, SCOTCH_STRATDEFAULT,
                                          (SCOTCH_Num)parts, 0.01) == 0,
            PM_ERR_INTERNAL, "SCOTCH_stratGraphMapBuild failed");
  api.SCOTCH_randomSeed(1);
  api.SCOTCH_randomReset();
  PM_ENSURE(api.SCOTCH_graphPart(&graph, (SCOTCH_Num)parts, &strat, to) == 0,
            PM_ERR_INTERNAL, "SCOTCH_graphPart failed (%ld vertices, %d parts)",
            n, parts);
  for (long i = 0; i < n; i++) part[i] = (int)to[i];
done:
  if (strat_made) api.SCOTCH_stratExit(&strat);
  if (graph_made) api.SCOTCH_graphExit(&graph);
  free(vert);
  free(edge);
  free(velo);
  free(to);
  return ret;
}
