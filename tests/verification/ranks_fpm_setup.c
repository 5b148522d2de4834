/* FPM's setup across ranks where rank 0 does not keep the whole model (as
 * when every rank writes its own frames): run under mpirun
 * (tests/verification/ranks-fpm.sh), rank 0 meshes the scene's domain and
 * builds its cells, and fpm_par_create is called with no whole model on
 * any rank.  It checks that
 *  - rank 0 lets its whole mesh and cells go (the cells freed, the mesh
 *    replaced by its surfaces' names), and every other rank holds those
 *    names and no mesh;
 *  - every rank's share is the share cut from the whole model, which rank
 *    0 builds afterwards on one process (fpm_share_create, the run's
 *    partition): every array bit for bit (a digest of each);
 *  - the ghosts' displacements come from their owners: each own point's
 *    index sent through the share's exchange reaches every ghost of it.
 * Usage: ranks_fpm_setup SCENE [KEY=VALUE...]; prints a line per check and
 * exits 0 when all hold. */
#include <mpi.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_backend.h"
#include "fpm_exchange.h"
#include "fpm_par.h"
#include "fpm_share.h"
#include "fpm_share_testing.h"
#include "pm_app.h"
#include "pm_par.h"
#include "pm_par_mpi.h"
#include "pm_petsc.h"
#include "pm_scene.h"
#include "ranks_testing.h"

static uint64_t fnv(uint64_t h, const void *p, size_t n) {
  const unsigned char *b = p;
  for (size_t k = 0; k < n; k++) {
    h ^= b[k];
    h *= 1099511628211ull;
  }
  return h;
}

/* The digests of share m: its counts, then each array's, then its
 * volumes' (d[DIGESTS]); the arrays' names into names where not NULL. */
#define DIGESTS (FPM_SHARE_ARRAYS + 2)
static void share_digest(const fpm_model *m, uint64_t *d, const char **names) {
  const uint64_t h0 = 1469598103934665603ull;
  const long counts[8] = {m->n,   m->n_own,  m->n_flux,    m->n_stress,
                          m->nnz, m->n_dpts, m->n_tfacets, m->n_cdofs};
  fpm_share_array a[FPM_SHARE_ARRAYS];
  const int na = fpm_share_arrays(m, a);
  memset(d, 0, sizeof(uint64_t) * DIGESTS);
  d[0] = fnv(h0, counts, sizeof counts);
  for (int k = 0; k < na; k++) {
    const char held = a[k].data != NULL;
    d[1 + k] = fnv(h0, &held, 1);
    if (held) d[1 + k] = fnv(d[1 + k], a[k].data, a[k].bytes);
    if (names) names[1 + k] = a[k].name;
  }
  d[DIGESTS - 1] = fnv(h0, m->dual->volume, sizeof(double) * (size_t)m->n);
  if (names) {
    names[0] = "counts";
    names[DIGESTS - 1] = "volume";
  }
}

/* Rank 0: the digests of every rank's share (ref[size * DIGESTS]) cut
 * from the whole model, built anew on one process, under the run's
 * partition owner. */
static int reference(const pm_scene *sc, const int *owner, uint64_t *ref) {
  fpm_sim *sim = NULL;
  if (fpm_sim_create(sc, &sim)) return 1;
  for (int r = 0; r < pm_par_size(); r++) {
    fpm_model *cut = NULL;
    if (fpm_share_create(sim->model, owner, r, &cut)) return 1;
    share_digest(cut, ref + (size_t)r * DIGESTS, NULL);
    fpm_model_destroy(cut);
  }
  fpm_sim_destroy(sim);
  return 0;
}

/* Every ghost of share m receives its owner's index of each point,
 * through the share's exchange. */
static bool ghosts_reached(const fpm_model *m) {
  double *u = malloc(sizeof(double) * 3 * (size_t)(m->n + 1));
  bool ok = u != NULL;
  for (long i = 0; ok && i < m->n; i++)
    for (int c = 0; c < 3; c++)
      u[3 * i + c] = i < m->n_own ? 3.0 * m->gid[i] + c : -1;
  if (u) fpm_exchange_ghosts(m->xc, u);
  for (long i = m->n_own; ok && i < m->n; i++)
    for (int c = 0; c < 3; c++) ok = ok && u[3 * i + c] == 3.0 * m->gid[i] + c;
  free(u);
  return ok;
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: ranks_fpm_setup SCENE [KEY=VALUE...]\n");
    return 2;
  }
  /* PETSc (the partitioner) started on every rank: rank 0 partitions
   * alone below. */
  if (pm_app_init() || pm_par_init(&argc, &argv) ||
      pm_par_attach(MPI_COMM_WORLD) || pm_petsc_init()) {
    fprintf(stderr, "%s\n", pm_error_message());
    return 2;
  }
  const int size = pm_par_size(), root = pm_par_root();
  pm_scene *sc = NULL;
  if (pm_scene_load(argv[1], argc - 2, (const char *const *)argv + 2, &sc)) {
    if (root) fprintf(stderr, "%s\n", pm_error_message());
    return 2;
  }
  if (size < 2) {
    fprintf(stderr, "ranks_fpm_setup: run it under mpirun with 2 or more "
                    "ranks\n");
    return 2;
  }
  uint64_t *ref = calloc((size_t)size * DIGESTS, sizeof *ref);
  uint64_t *got = calloc((size_t)size * DIGESTS, sizeof *got);
  /* Rank 0 meshes the domain and builds its cells, and keeps no model. */
  fpm_sim *sim = NULL;
  int bad = root ? fpm_sim_create(sc, &sim) != PM_SUCCESS : 0;
  MPI_Bcast(&bad, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (bad) {
    if (root) fprintf(stderr, "%s\n", pm_error_message());
    return 2;
  }
  if (root) {
    fpm_state_destroy(sim->state);
    fpm_model_destroy(sim->model);
    sim->state = NULL;
    sim->model = NULL;
  }
  gm_mesh *mesh = root ? sim->mesh : NULL;
  gm_dual *cells = root ? sim->dual : NULL;
  const int surfaces = root ? mesh->n_surfaces : 0;
  fpm_model *share = NULL;
  if (fpm_par_create(sc, &mesh, &cells, NULL, &share)) {
    if (root) fprintf(stderr, "%s\n", pm_error_message());
    return 2;
  }
  if (root) sim->mesh = mesh, sim->dual = cells;
  int all_surfaces = surfaces;
  MPI_Bcast(&all_surfaces, 1, MPI_INT, 0, MPI_COMM_WORLD);
  expect(cells == NULL, "no rank holds the whole cells once the parts are "
                        "made (rank 0 freed its own)");
  expect(mesh && mesh->n_nodes == 0 && !mesh->x && mesh->n_cells == 0 &&
             !mesh->cells && mesh->n_surfaces == all_surfaces,
         "every rank holds the mesh's surface names and no nodes nor cells");
  bad = root ? reference(sc, fpm_par_owner(share), ref) : 0;
  MPI_Bcast(&bad, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (bad) {
    if (root) fprintf(stderr, "%s\n", pm_error_message());
    return 2;
  }
  uint64_t mine[DIGESTS];
  const char *names[DIGESTS];
  share_digest(share, mine, names);
  MPI_Gather(mine, DIGESTS, MPI_UINT64_T, got, DIGESTS, MPI_UINT64_T, 0,
             MPI_COMM_WORLD);
  int same = 1;
  if (root)
    for (int r = 0; r < size; r++)
      for (int k = 0; k < DIGESTS; k++)
        if (got[r * DIGESTS + k] != ref[r * DIGESTS + k]) {
          printf("rank %d: %s differs from the share cut from the whole\n", r,
                 names[k]);
          same = 0;
        }
  MPI_Bcast(&same, 1, MPI_INT, 0, MPI_COMM_WORLD);
  char what[160];
  snprintf(what, sizeof what,
           "every rank's share (%d ranks) is the share cut from the whole "
           "model, bit for bit",
           size);
  expect(same, what);
  expect(ghosts_reached(share),
         "every ghost receives its owner's value through the exchange");
  fpm_model_destroy(share);
  if (root) {
    fpm_sim_destroy(sim);
  } else {
    gm_mesh_destroy(mesh);
  }
  free(ref);
  free(got);
  pm_scene_destroy(sc);
  if (root) printf("%d failed\n", failures);
  return failures != 0;
}
