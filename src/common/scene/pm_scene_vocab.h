/* pm_scene_vocab: the shared keys of a scene and the checks across them.
 * Private to the scene loader. */
#ifndef PM_SCENE_VOCAB_H
#define PM_SCENE_VOCAB_H

#include "pm_reader.h"
#include "pm_scene.h"

/* The top-level keys every method shares. */
extern const pm_key pm_scene_keys[];

/* The keys every material has (name, model, density, artificial
 * viscosity); the rest are its model's.  PM_MATERIAL_KEYS entries with the
 * end. */
#define PM_MATERIAL_KEYS 6
extern const pm_key pm_scene_material_keys[PM_MATERIAL_KEYS];

/* The materials list (a CUSTOM key of pm_scene_keys): each entry against
 * the common keys and its model's, then its model's checks. */
pm_err pm_scene_read_materials(pm_reader *r, int id, const char *path,
                               const pm_key *k, void *dst);

/* CUSTOM readers of pm_scene_keys (pm_scene_readers.c), each failing at
 * the key at fault: the dimension (2 or 3, also into r->dimension), a
 * material point's fibres (1 to PM_FIBRES_MAX non-zero directions,
 * normalized), a body's region (an expression in x, y, z, or domain). */
pm_err pm_scene_read_dimension(pm_reader *r, int id, const char *path,
                               const pm_key *k, void *dst);
pm_err pm_scene_read_fibres(pm_reader *r, int id, const char *path,
                            const pm_key *k, void *dst);
pm_err pm_scene_read_region(pm_reader *r, int id, const char *path,
                            const pm_key *k, void *dst);

/* A load curve (curve, body_curve): an expression of t, or a .csv table
 * relative to the scene's folder, a bad row failing at the key with the
 * table's FILE:LINE. */
pm_err pm_scene_read_curve(pm_reader *r, int id, const char *path,
                           const pm_key *k, void *dst);

/* Release of an expression key (dst: a pm_expr *, set to NULL). */
void pm_scene_release_expr(void *dst);
/* Release of a curve key (dst: a pm_curve *, set to NULL). */
void pm_scene_release_curve(void *dst);

/* After reading: defaults that depend on other keys, names resolved to
 * indices, and the checks across keys, each failing at the key at fault. */
pm_err pm_scene_finish(pm_reader *r, pm_scene *s);

/* domain.box: the one given, checked, or for FPM without it the bounds of
 * the body that bounds the scene (pm_scene_domain.c; after the bodies'
 * paths are resolved). */
pm_err pm_scene_finish_domain(pm_reader *r, pm_scene *s);

#endif
