/* gm_gmsh_read: a gmsh model, built in memory or read from a file, as
 * linear simplices and the named physical groups on their boundary.  The
 * one reader of gmsh meshes for gm_mesh and gm_volume. */
#include "gm_gmsh.h"
#include "gm_trisurf.h"

#include <errno.h>
#include "gm_gmsh_api.h" /* gmshc.h, through the table */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* How messages name the model. */
static const char *label(const char *name) {
  return name ? name : "(model in memory)";
}

static const char *simplices(int dim) {
  return dim == 3 ? "tetrahedra" : dim == 2 ? "triangles" : "line segments";
}

void gm_gmsh_mesh_free(gm_gmsh_mesh *m) {
  if (!m) return;
  free(m->x);
  free(m->elem);
  if (m->group_name)
    for (int g = 0; g < m->n_groups; g++) free(m->group_name[g]);
  free(m->group_name);
  free(m->group_ptr);
  free(m->group_face);
  memset(m, 0, sizeof *m);
}

/* Nodes per element of gmsh type `type` (corners and higher-order nodes),
 * after checking that it is a simplex of dimension dim.  group names the
 * physical group in the message (NULL: the volume itself). */
static pm_err simplex_nodes(const char *name, int type, int dim,
                            const char *group, size_t *per) {
  pm_err ret = PM_SUCCESS;
  char *tname = NULL;
  double *local = NULL;
  size_t n_local = 0;
  int edim = 0, order = 0, all = 0, corners = 0, ierr = 0;
  gmshModelMeshGetElementProperties(type, &tname, &edim, &order, &all, &local,
                                    &n_local, &corners, &ierr);
  GM_GMSH_CHECK("reading element properties in", name);
  PM_ENSURE(corners == dim + 1, PM_ERR_UNSUPPORTED,
            "'%s' has %s elements (gmsh type %d)%s%s%s: only %s are "
            "supported",
            label(name), tname ? tname : "?", type,
            group ? " in physical group '" : "", group ? group : "",
            group ? "'" : "", simplices(dim));
  PM_ENSURE(all >= corners, PM_ERR_MESH,
            "gmsh gives %d nodes to its element type %d of %d corners", all,
            type, corners);
  *per = (size_t)all;
done:
  if (tname) gmshFree(tname);
  if (local) gmshFree(local);
  return ret;
}

/* Appends the corner node tags of every element of dimension d on model
 * entity `entity` (-1: all of them) to *tags, d + 1 per element (*tags
 * grows with realloc; *n counts the elements). */
static pm_err append_corners(const char *name, int d, int entity,
                             const char *group, size_t **tags, long *n) {
  pm_err ret = PM_SUCCESS;
  int ierr = 0, *types = NULL;
  size_t n_types = 0, *etags = NULL, n_etags = 0, *enodes = NULL;
  size_t n_enodes = 0;
  const size_t npc = (size_t)d + 1;
  gmshModelMeshGetElementTypes(&types, &n_types, d, entity, &ierr);
  GM_GMSH_CHECK("listing the element types of", name);
  for (size_t t = 0; t < n_types; t++) {
    size_t per = 0;
    PM_TRY(simplex_nodes(name, types[t], d, group, &per));
    gmshModelMeshGetElementsByType(types[t], &etags, &n_etags, &enodes,
                                   &n_enodes, entity, 0, 1, &ierr);
    GM_GMSH_CHECK("reading the elements of", name);
    PM_ENSURE(n_enodes == per * n_etags, PM_ERR_MESH,
              "gmsh returned %zu nodes for %zu elements of '%s'", n_enodes,
              n_etags, label(name));
    if (n_etags > 0) {
      size_t *grown =
          realloc(*tags, sizeof **tags * npc * ((size_t)*n + n_etags));
      PM_ENSURE(grown, PM_ERR_MEMORY, "no memory for %zu elements of '%s'",
                (size_t)*n + n_etags, label(name));
      *tags = grown;
    }
    /* gmsh lists an element's corner nodes first. */
    for (size_t e = 0; e < n_etags; e++, (*n)++)
      memcpy(*tags + npc * (size_t)*n, enodes + per * e, sizeof **tags * npc);
    gmshFree(etags);
    gmshFree(enodes);
    etags = enodes = NULL;
  }
done:
  if (types) gmshFree(types);
  if (etags) gmshFree(etags);
  if (enodes) gmshFree(enodes);
  return ret;
}

pm_err gm_gmsh_check_nodes(const char *name, const double *x, long n) {
  for (long i = 0; i < 3 * n; i++)
    PM_CHECK(isfinite(x[i]), PM_ERR_MESH,
             "'%s' has node %ld at (%g, %g, %g): expected finite coordinates",
             label(name), i / 3, x[i - i % 3], x[i - i % 3 + 1],
             x[i - i % 3 + 2]);
  return PM_SUCCESS;
}

/* Triangles must lie in z = 0: a surface mesh elsewhere projected onto the
 * plane would give nonsense.  Then z is set to 0 exactly. */
static pm_err check_plane(const char *name, gm_gmsh_mesh *m) {
  double ext = 0.0, zmax = 0.0;
  for (long i = 0; i < m->n_nodes; i++) {
    for (int k = 0; k < 2; k++)
      ext = fmax(ext, fabs(m->x[3 * i + k] - m->x[k]));
    zmax = fmax(zmax, fabs(m->x[3 * i + 2]));
  }
  PM_CHECK(zmax <= 1e-9 * ext, PM_ERR_MESH,
           "'%s': 2D triangles must lie in the z = 0 plane (a node has |z| = "
           "%g, the xy extent is %g)",
           label(name), zmax, ext);
  for (long i = 0; i < m->n_nodes; i++) m->x[3 * i + 2] = 0.0;
  return PM_SUCCESS;
}

/* Physical groups of dimension dim - 1, their faces numbered as nodes
 * numbers them (-1 for a node no element uses). */
static pm_err read_groups(const char *name, int dim, const gm_gmsh_nodes *nodes,
                          gm_gmsh_mesh *out) {
  pm_err ret = PM_SUCCESS;
  int ierr = 0, *dimtags = NULL, *ents = NULL;
  size_t n_dimtags = 0, n_ents = 0, *ftag = NULL;
  char *pname = NULL;
  long nf = 0;
  const int d = dim - 1;
  gmshModelGetPhysicalGroups(&dimtags, &n_dimtags, d, &ierr);
  GM_GMSH_CHECK("listing the physical groups of", name);
  const int ng = (int)(n_dimtags / 2);
  PM_TRY(PM_ALLOC(out->group_name, ng, "physical group names"));
  PM_TRY(PM_ALLOC(out->group_ptr, ng + 1, "physical groups"));
  out->n_groups = ng;
  for (int g = 0; g < ng; g++) {
    const int tag = dimtags[2 * g + 1];
    gmshModelGetPhysicalName(d, tag, &pname, &ierr);
    GM_GMSH_CHECK("reading the physical names of", name);
    char fallback[32];
    snprintf(fallback, sizeof fallback, "surface-%d", tag);
    out->group_name[g] = strdup(pname && pname[0] ? pname : fallback);
    PM_ENSURE(out->group_name[g], PM_ERR_MEMORY, "no memory for a name");
    gmshFree(pname);
    pname = NULL;
    gmshModelGetEntitiesForPhysicalGroup(d, tag, &ents, &n_ents, &ierr);
    GM_GMSH_CHECK("reading the physical groups of", name);
    for (size_t e = 0; e < n_ents; e++)
      PM_TRY(append_corners(name, d, ents[e], out->group_name[g], &ftag, &nf));
    gmshFree(ents);
    ents = NULL;
    out->group_ptr[g + 1] = nf;
  }
  PM_TRY(PM_ALLOC(out->group_face, (size_t)dim * nf, "physical group faces"));
  for (size_t k = 0; k < (size_t)dim * nf; k++)
    out->group_face[k] = gm_gmsh_node_number(nodes, ftag[k]);
done:
  free(ftag);
  if (dimtags) gmshFree(dimtags);
  if (ents) gmshFree(ents);
  if (pname) gmshFree(pname);
  return ret;
}

/* ---- node numbering ------------------------------------------------------ */

typedef struct {
  size_t tag, at; /* a node's tag and its place in gmsh's list */
} tag_at;

static int tag_order(const void *a, const void *b) {
  const size_t s = ((const tag_at *)a)->tag, t = ((const tag_at *)b)->tag;
  return (s > t) - (s < t);
}

/* Index of tag in nodes->tag (sorted), -1 when absent. */
static long tag_index(const gm_gmsh_nodes *nodes, size_t tag) {
  size_t lo = 0, hi = nodes->n;
  while (lo < hi) {
    const size_t mid = lo + (hi - lo) / 2;
    if (nodes->tag[mid] < tag)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo < nodes->n && nodes->tag[lo] == tag ? (long)lo : -1;
}

long gm_gmsh_node_number(const gm_gmsh_nodes *nodes, size_t tag) {
  const long j = tag_index(nodes, tag);
  return j >= 0 ? nodes->number[j] : -1;
}

void gm_gmsh_nodes_free(gm_gmsh_nodes *nodes) {
  free(nodes->tag);
  free(nodes->number);
  memset(nodes, 0, sizeof *nodes);
}

pm_err gm_gmsh_corners(const char *name, const size_t *ctag, size_t nc,
                       long *corner, double **x, long *nn,
                       gm_gmsh_nodes *nodes) {
  pm_err ret = PM_SUCCESS;
  int ierr = 0;
  size_t *tags = NULL, n_tags = 0, n_coord = 0, n_param = 0;
  double *coord = NULL, *param = NULL;
  tag_at *sorted = NULL;
  long *number = NULL; /* by place in gmsh's list */
  *x = NULL;
  *nn = 0;
  memset(nodes, 0, sizeof *nodes);
  gmshModelMeshGetNodes(&tags, &n_tags, &coord, &n_coord, &param, &n_param, -1,
                        -1, 0, 0, &ierr);
  GM_GMSH_CHECK("reading the nodes of", name);
  PM_ENSURE(n_coord == 3 * n_tags, PM_ERR_MESH,
            "gmsh returned %zu coordinates for %zu nodes of '%s'", n_coord,
            n_tags, label(name));
  PM_TRY(PM_ALLOC(sorted, n_tags, "node tags"));
  PM_TRY(PM_ALLOC(number, n_tags, "node numbers"));
  for (size_t i = 0; i < n_tags; i++) {
    sorted[i] = (tag_at){tags[i], i};
    number[i] = -1;
  }
  /* A model without nodes: no array to sort (qsort takes none, even of
   * no elements). */
  if (n_tags > 1) qsort(sorted, n_tags, sizeof *sorted, tag_order);
  PM_TRY(PM_ALLOC(nodes->tag, n_tags, "node tags"));
  PM_TRY(PM_ALLOC(nodes->number, n_tags, "node numbers"));
  nodes->n = n_tags;
  for (size_t j = 0; j < n_tags; j++) nodes->tag[j] = sorted[j].tag;
  /* corner[k] first holds its node's place, number[] -2 for a corner. */
  for (size_t k = 0; k < nc; k++) {
    const long j = tag_index(nodes, ctag[k]);
    PM_ENSURE(j >= 0, PM_ERR_MESH,
              "an element of '%s' refers to node %zu without coordinates",
              label(name), ctag[k]);
    corner[k] = (long)sorted[j].at;
    number[sorted[j].at] = -2;
  }
  long count = 0;
  for (size_t i = 0; i < n_tags; i++)
    if (number[i] == -2) number[i] = count++;
  PM_TRY(PM_ALLOC(*x, 3 * (size_t)count, "mesh coordinates"));
  for (size_t i = 0; i < n_tags; i++)
    if (number[i] >= 0)
      memcpy(*x + 3 * number[i], coord + 3 * i, 3 * sizeof *coord);
  for (size_t k = 0; k < nc; k++) corner[k] = number[corner[k]];
  for (size_t j = 0; j < n_tags; j++) nodes->number[j] = number[sorted[j].at];
  *nn = count;
done:
  if (ret) {
    free(*x);
    *x = NULL;
    gm_gmsh_nodes_free(nodes);
  }
  free(sorted);
  free(number);
  if (tags) gmshFree(tags);
  if (coord) gmshFree(coord);
  if (param) gmshFree(param);
  return ret;
}

pm_err gm_gmsh_read(const char *name, int dim, bool groups, gm_gmsh_mesh *out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_gmsh_read: out is NULL");
  memset(out, 0, sizeof *out);
  PM_CHECK(dim == 2 || dim == 3, PM_ERR_ARG,
           "mesh dimension must be 2 or 3 (got %d) for '%s'", dim, label(name));
  pm_err ret = PM_SUCCESS;
  int ierr = 0;
  size_t *ctag = NULL;
  gm_gmsh_nodes nodes = {0};
  long n = 0, nn = 0;
  const size_t npc = (size_t)dim + 1;
  out->dim = dim;
  PM_TRY(append_corners(name, dim, -1, NULL, &ctag, &n));
  if (n == 0) {
    int model_dim = gmshModelGetDimension(&ierr);
    PM_FAIL(PM_ERR_MESH,
            "'%s' gives no %s (the model's dimension is %d): is it a %dD "
            "solid?",
            label(name), simplices(dim), ierr ? -1 : model_dim, dim);
  }
  PM_TRY(PM_ALLOC(out->elem, npc * (size_t)n, "mesh elements"));
  PM_TRY(gm_gmsh_corners(name, ctag, npc * (size_t)n, out->elem, &out->x, &nn,
                         &nodes));
  out->n_nodes = nn;
  out->n_elems = n;
  PM_TRY(gm_gmsh_check_nodes(name, out->x, nn));
  if (dim == 2) PM_TRY(check_plane(name, out));
  if (groups) PM_TRY(read_groups(name, dim, &nodes, out));
done:
  if (ret) gm_gmsh_mesh_free(out);
  free(ctag);
  gm_gmsh_nodes_free(&nodes);
  return ret;
}

pm_err gm_gmsh_check_file(const char *path, const char *what) {
  struct stat st;
  PM_CHECK(stat(path, &st) == 0, PM_ERR_IO, "cannot open %s '%s': %s", what,
           path, strerror(errno));
  PM_CHECK(!S_ISDIR(st.st_mode), PM_ERR_IO, "%s '%s' is a directory", what,
           path);
  FILE *f = fopen(path, "rb");
  PM_CHECK(f, PM_ERR_IO, "cannot read %s '%s': %s", what, path,
           strerror(errno));
  fclose(f);
  return gm_geo_check(path);
}

/* Open path in session (which the caller ends whatever happens): its
 * element types of dimension dim, counted. */
static pm_err open_counting(const char *path, int dim, gm_gmsh_session *session,
                            size_t *n_types) {
  pm_err ret = PM_SUCCESS;
  int ierr = 0, *types = NULL;
  *n_types = 0;
  PM_TRY(gm_gmsh_begin(session, path));
  gmshOpen(path, &ierr);
  GM_GMSH_CHECK("reading", path);
  gmshModelMeshGetElementTypes(&types, n_types, dim, -1, &ierr);
  GM_GMSH_CHECK("listing the element types of", path);
done:
  if (types) gmshFree(types);
  return ret;
}

/* Whether the open model's triangles (gmsh type 2) close a surface,
 * consistently oriented (gm_trisurf_closed, on their node tags). */
static pm_err triangles_closed(const char *path, bool *closed) {
  pm_err ret = PM_SUCCESS;
  int ierr = 0;
  size_t *etag = NULL, *ntag = NULL, n_e = 0, n_n = 0;
  gm_trisurf tags = {.n_points = 0};
  *closed = false;
  gmshModelMeshGetElementsByType(2, &etag, &n_e, &ntag, &n_n, -1, 0, 1, &ierr);
  GM_GMSH_CHECK("reading the triangles of", path);
  tags.n_tris = (long)(n_n / 3);
  if (tags.n_tris < 4) goto done;
  PM_TRY(PM_ALLOC(tags.tri, 3 * (size_t)tags.n_tris, "surface triangles"));
  for (size_t k = 0; k < 3 * (size_t)tags.n_tris; k++) {
    tags.tri[k] = (long)ntag[k];
    if (tags.tri[k] >= tags.n_points) tags.n_points = tags.tri[k] + 1;
  }
  *closed = gm_trisurf_closed(&tags, NULL, 0);
done:
  free(tags.tri);
  if (etag) gmshFree(etag);
  if (ntag) gmshFree(ntag);
  return ret;
}

/* A file that holds a closed, consistently oriented surface mesh and no
 * volume (.stl, .ply, a .msh of triangles): the volume it closes, its
 * triangles kept as the boundary (gmsh classifies them into surfaces at
 * 40-degree edges and builds a volume on all of them).  *closed: whether
 * there was one to close. */
static pm_err close_surface_mesh(const char *path, bool *closed) {
  pm_err ret = PM_SUCCESS;
  int ierr = 0, *vol = NULL, *types = NULL, *surf = NULL, *tags = NULL;
  size_t n_vol = 0, n_types = 0, n_surf = 0;
  *closed = false;
  gmshModelGetEntities(&vol, &n_vol, 3, &ierr);
  GM_GMSH_CHECK("listing the volumes of", path);
  gmshModelMeshGetElementTypes(&types, &n_types, 2, -1, &ierr);
  GM_GMSH_CHECK("listing the element types of", path);
  if (n_vol > 0 || n_types == 0) goto done;
  bool whole = false;
  PM_TRY(triangles_closed(path, &whole));
  if (!whole) goto done; /* no volume in it: "gives no tetrahedra" */
  const double pi = 3.14159265358979323846;
  gmshModelMeshClassifySurfaces(40 * pi / 180, 1, 0, pi, 0, &ierr);
  GM_GMSH_CHECK("classifying the surface mesh of", path);
  gmshModelMeshCreateGeometry(NULL, 0, &ierr);
  GM_GMSH_CHECK("building surfaces from the mesh of", path);
  gmshModelGetEntities(&surf, &n_surf, 2, &ierr);
  GM_GMSH_CHECK("listing the surfaces of", path);
  PM_ENSURE(n_surf > 0, PM_ERR_MESH, "'%s': no surface to close", path);
  PM_TRY(PM_ALLOC(tags, n_surf / 2, "surface tags"));
  for (size_t k = 0; k < n_surf / 2; k++) tags[k] = surf[2 * k + 1];
  int loop = gmshModelGeoAddSurfaceLoop(tags, n_surf / 2, -1, &ierr);
  GM_GMSH_CHECK("closing the surfaces of", path);
  gmshModelGeoAddVolume(&loop, 1, -1, &ierr);
  GM_GMSH_CHECK("adding the volume of", path);
  gmshModelGeoSynchronize(&ierr);
  GM_GMSH_CHECK("adding the volume of", path);
  *closed = true;
done:
  if (vol) gmshFree(vol);
  if (types) gmshFree(types);
  if (surf) gmshFree(surf);
  free(tags);
  return ret;
}

pm_err gm_gmsh_load_here(const char *path, int dim, double h, gm_sizes rule,
                         bool groups, gm_gmsh_mesh *out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_gmsh_load: out is NULL");
  memset(out, 0, sizeof *out);
  PM_CHECK(path && path[0], PM_ERR_ARG, "no volume file name");
  PM_CHECK(dim == 2 || dim == 3, PM_ERR_ARG,
           "volume dimension must be 2 or 3 (got %d) for '%s'", dim, path);
  PM_CHECK(isfinite(h), PM_ERR_ARG,
           "mesh size h must be finite (got %g) for '%s'", h, path);
  PM_CALL(gm_gmsh_check_file(path, "volume file"));
  pm_err ret = PM_SUCCESS;
  int ierr = 0;
  size_t n_types = 0;
  gm_gmsh_session session = {.threads = 0, .open = false};
  PM_TRY(open_counting(path, dim, &session, &n_types));
  double factor = 1;
  if (n_types == 0) {
    bool closed = false;
    if (dim == 3) PM_TRY(close_surface_mesh(path, &closed));
    /* a closed surface mesh keeps its triangles: none to scale */
    if (closed && rule == GM_SIZES_SCALE) rule = GM_SIZES_REPLACE;
    if (h > 0.0) PM_TRY(gm_gmsh_sizes(rule, h, path, &factor));
    gmshModelMeshGenerate(dim, &ierr);
    GM_GMSH_CHECK("meshing", path);
  }
  PM_TRY(gm_gmsh_read(path, dim, groups, out));
  out->meshed = n_types == 0;
  out->size_factor = factor;
done:
  gm_gmsh_end(&session);
  return ret;
}

/* Whether line (from fgets) starts with word and ends there. */
static bool line_is(const char *line, const char *word) {
  size_t n = strlen(word);
  return strncmp(line, word, n) == 0 &&
         (line[n] == '\n' || line[n] == '\r' || line[n] == '\0');
}

long gm_msh_node_count(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) return -1;
  char line[4096];
  long count = -1;
  double version = 0;
  int binary = -1;
  bool at_start = true; /* line holds the start of a line of the file */
  while (fgets(line, sizeof line, f)) {
    const bool start = at_start;
    at_start = strchr(line, '\n') != NULL;
    if (!start) continue;
    if (line_is(line, "$MeshFormat")) {
      if (!fgets(line, sizeof line, f) ||
          sscanf(line, "%lf %d", &version, &binary) != 2)
        break;
      at_start = strchr(line, '\n') != NULL;
    } else if (line_is(line, "$Nodes")) {
      /* 2.x: the count alone; 4.x: blocks, nodes, smallest and largest
       * tag (in binary 4.x the header is binary: not read here). */
      if (binary != 0 && !(binary == 1 && version < 3)) break;
      long a = -1, b = -1;
      if (!fgets(line, sizeof line, f)) break;
      int got = sscanf(line, "%ld %ld", &a, &b);
      if (version >= 4 && got == 2)
        count = b;
      else if (version > 0 && version < 3 && got >= 1)
        count = a;
      break;
    }
  }
  fclose(f);
  return count >= 0 ? count : -1;
}

pm_err gm_file_bounds_here(const char *path, int dim, double lo[3],
                           double hi[3]) {
  PM_CHECK(path && path[0], PM_ERR_ARG, "no geometry file name");
  PM_CALL(gm_gmsh_check_file(path, "geometry file"));
  pm_err ret = PM_SUCCESS;
  int ierr = 0;
  size_t n_types = 0;
  gm_gmsh_mesh raw = {.dim = 0};
  gm_gmsh_session session = {.threads = 0, .open = false};
  PM_TRY(open_counting(path, dim, &session, &n_types));
  if (n_types > 0) {
    /* a mesh: the corners of its elements of dimension dim (what FPM
     * meshes; a .msh's entity boxes are what the file says) */
    PM_TRY(gm_gmsh_read(path, dim, false, &raw));
    for (int c = 0; c < 3; c++) lo[c] = hi[c] = raw.x[c];
    for (long k = 3; k < 3 * raw.n_nodes; k++) {
      lo[k % 3] = fmin(lo[k % 3], raw.x[k]);
      hi[k % 3] = fmax(hi[k % 3], raw.x[k]);
    }
  } else {
    gmshModelGetBoundingBox(-1, -1, &lo[0], &lo[1], &lo[2], &hi[0], &hi[1],
                            &hi[2], &ierr);
    GM_GMSH_CHECK("bounding", path);
  }
  for (int c = 0; c < dim; c++)
    PM_ENSURE(isfinite(lo[c]) && isfinite(hi[c]) && hi[c] > lo[c], PM_ERR_MESH,
              "'%s' bounds nothing along %c ([%g, %g])", path, "xyz"[c], lo[c],
              hi[c]);
  if (dim == 2) lo[2] = hi[2] = 0;
done:
  gm_gmsh_mesh_free(&raw);
  gm_gmsh_end(&session);
  return ret;
}
