/* gm_gmsh: one gmsh session setup for every geometry module. */
#include "gm_gmsh.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>

#include "gm_gmsh_api.h"
#include "pm_isolate.h"
#include "pm_omp.h"
#include "pm_scene.h"

/* A scene's discretization.mesh_sizes is a gm_sizes. */
_Static_assert((int)GM_SIZES_SCALE == (int)PM_MESH_SIZES_SCALE &&
                   (int)GM_SIZES_REPLACE == (int)PM_MESH_SIZES_REPLACE &&
                   (int)GM_SIZES_FILE == (int)PM_MESH_SIZES_FILE,
               "gm_sizes and PM_MESH_SIZES_* in one order");

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define GM_GMSH_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(GM_GMSH_ASAN)
/* gmsh 4.8 and OpenCASCADE leak a little on their own: meshing curved
 * surfaces (meshGFace), the .geo parser after a syntax error (its Malloc),
 * STEP reading and writing (OpenCASCADE's libTK*), and an STL's triangles
 * once classified into surfaces (GModel::readSTL's discrete face and the
 * edges classifyFaces makes, which the new surfaces replace).  A sanitizer
 * build (detect_leaks=1) of any program that meshes through this module ignores
 * exactly those, so that a leak of ours, or an array from the gmsh API left
 * without gmshFree, still fails. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) {
  return "leak:meshGFace\nleak:^Malloc(\nleak:libTK\nleak:GModel::readSTL\n"
         "leak:classifyFaces\nleak:discreteFace::_createGeometryFromSTL\n";
}
#endif

pm_err gm_gmsh_fail(const char *what, const char *path) {
  char *msg = NULL;
  int ierr = 0;
  gmshLoggerGetLastError(&msg, &ierr);
  const char *text =
      (ierr == 0 && msg && msg[0]) ? msg : "(no message from gmsh)";
  pm_err e =
      path ? PM_ERROR(PM_ERR_MESH, "gmsh: %s '%s' failed: %s", what, path, text)
           : PM_ERROR(PM_ERR_MESH, "gmsh: %s failed: %s", what, text);
  if (msg) gmshFree(msg);
  return e;
}

typedef struct {
  const char *name;
  double value;
} gm_option;

static pm_err set_options(const gm_option *opts, size_t n, const char *path) {
  int ierr = 0;
  for (size_t i = 0; i < n; i++) {
    gmshOptionSetNumber(opts[i].name, opts[i].value, &ierr);
    if (ierr) return gm_gmsh_fail(opts[i].name, path);
  }
  return PM_SUCCESS;
}

pm_err gm_gmsh_preload(const char *need) { return gm_gmsh_api_load(need); }

/* gmsh initialized by gm_gmsh_warm and not yet taken by a session. */
static bool warm = false;

pm_err gm_gmsh_warm(void) {
  int ierr = 0;
  if (warm) return PM_SUCCESS;
  PM_CALL(gm_gmsh_preload("reading gmsh files"));
  const int threads = pm_omp_threads();
  gmshInitialize(0, NULL, 0, &ierr);
  pm_omp_set_threads(threads);
  if (ierr) return gm_gmsh_fail("initialize", NULL);
  warm = true;
  return PM_SUCCESS;
}

pm_err gm_gmsh_begin(gm_gmsh_session *s, const char *path) {
  static const gm_option quiet[] = {
      {"General.Terminal", 0},
      {"General.NumThreads", 1},
      {"Mesh.RandomSeed", 1},
  };
  int ierr = 0;
  s->threads = 0;
  s->open = false;
  /* The library is opened here, by the first session: a run that never
   * meshes nor reads a gmsh file never maps it.  Without a file, the
   * session meshes the scene's domain.box (gm_mesh_box). */
  char need[512];
  if (path)
    snprintf(need, sizeof need, "reading '%s'", path);
  else
    snprintf(need, sizeof need, "meshing the box of domain.box");
  PM_CALL(gm_gmsh_api_load(need));
  /* gmsh sets the process-wide OpenMP thread count from its own option:
   * gm_gmsh_end puts ours back. */
  s->threads = pm_omp_threads();
  if (warm)
    warm = false; /* initialized ahead by gm_gmsh_warm, and unused */
  else
    gmshInitialize(0, NULL, 0, &ierr);
  if (ierr) return gm_gmsh_fail("initialize", path);
  s->open = true;
  /* gmsh resets every option at initialization: nothing leaks between
   * sessions. */
  return set_options(quiet, sizeof quiet / sizeof quiet[0], path);
}

void gm_gmsh_end(gm_gmsh_session *s) {
  int ierr = 0;
  if (s->open && !pm_isolate_in_child()) gmshFinalize(&ierr);
  s->open = false;
  if (s->threads > 0) pm_omp_set_threads(s->threads);
}

pm_err gm_gmsh_size(double h, const char *path) {
  const gm_option size[] = {
      {"Mesh.MeshSizeFromPoints", 0},
      {"Mesh.MeshSizeFromCurvature", 0},
      {"Mesh.MeshSizeExtendFromBoundary", 1},
      {"Mesh.MeshSizeMin", h},
      {"Mesh.MeshSizeMax", h},
  };
  return set_options(size, sizeof size / sizeof size[0], path);
}

/* The longest edge of the open model's mesh of its curves (0 without one),
 * which the caller then clears. */
static pm_err longest_curve_edge(const char *path, double *len) {
  pm_err ret = PM_SUCCESS;
  int ierr = 0;
  size_t *etag = NULL, *ntag = NULL, n_e = 0, n_n = 0;
  double *a = NULL, *b = NULL, *pa = NULL, *pb = NULL;
  size_t na = 0, nb = 0, npa = 0, npb = 0;
  *len = 0;
  gmshModelMeshGenerate(1, &ierr);
  GM_GMSH_CHECK("meshing the curves of", path);
  /* gmsh type 1: the two-node line */
  gmshModelMeshGetElementsByType(1, &etag, &n_e, &ntag, &n_n, -1, 0, 1, &ierr);
  GM_GMSH_CHECK("reading the curves' mesh of", path);
  for (size_t k = 0; k + 1 < n_n; k += 2) {
    gmshModelMeshGetNode(ntag[k], &a, &na, &pa, &npa, &ierr);
    GM_GMSH_CHECK("reading the curves' mesh of", path);
    gmshModelMeshGetNode(ntag[k + 1], &b, &nb, &pb, &npb, &ierr);
    GM_GMSH_CHECK("reading the curves' mesh of", path);
    if (na == 3 && nb == 3)
      *len = fmax(*len, hypot(hypot(a[0] - b[0], a[1] - b[1]), a[2] - b[2]));
    gmshFree(a);
    gmshFree(b);
    if (pa) gmshFree(pa);
    if (pb) gmshFree(pb);
    a = b = pa = pb = NULL;
  }
done:
  if (a) gmshFree(a);
  if (b) gmshFree(b);
  if (pa) gmshFree(pa);
  if (pb) gmshFree(pb);
  if (etag) gmshFree(etag);
  if (ntag) gmshFree(ntag);
  return ret;
}

pm_err gm_gmsh_sizes(gm_sizes rule, double h, const char *path,
                     double *factor) {
  double f = 1;
  if (rule == GM_SIZES_SCALE) {
    pm_err ret = PM_SUCCESS;
    int ierr = 0;
    double len = 0, was = 1;
    PM_TRY(longest_curve_edge(path, &len));
    gmshModelMeshClear(NULL, 0, &ierr);
    GM_GMSH_CHECK("clearing the curves' mesh of", path);
    if (len > 0 && isfinite(len)) {
      gmshOptionGetNumber("Mesh.MeshSizeFactor", &was, &ierr);
      GM_GMSH_CHECK("Mesh.MeshSizeFactor", path);
      double max = 0;
      gmshOptionGetNumber("Mesh.MeshSizeMax", &max, &ierr);
      GM_GMSH_CHECK("Mesh.MeshSizeMax", path);
      f = h / len;
      /* and at most h (gmsh multiplies the size it clamps to MeshSizeMax
       * by the factor): a curve shorter than its size is one edge, and a
       * file without sizes is meshed at gmsh's (the bounding box's) */
      const gm_option scaled[] = {{"Mesh.MeshSizeFactor", was * f},
                                  {"Mesh.MeshSizeMax", fmin(max, h / f)}};
      PM_TRY(set_options(scaled, 2, path));
    } else {
      rule = GM_SIZES_REPLACE;
    }
  done:
    if (ret) return ret;
  }
  if (rule == GM_SIZES_REPLACE) {
    f = 0;
    PM_CALL(gm_gmsh_size(h, path));
  }
  if (factor) *factor = f;
  return PM_SUCCESS;
}
