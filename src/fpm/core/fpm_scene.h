/* fpm_scene: the "fpm:" section of a scene (its keys, each with its
 * default) and what method fpm refuses in a scene. */
#ifndef FPM_SCENE_H
#define FPM_SCENE_H

#include "pm_backend.h"
#include "pm_scene.h"

/* Interior-penalty flux. */
typedef enum {
  FPM_FLUX_IIPG = 0, /* incomplete (the FPM paper's eq. 16) */
  FPM_FLUX_SIPG      /* symmetric: the force is the gradient of an energy */
} fpm_flux;

/* The reconstruction whose jump across an interface the penalty measures. */
typedef enum {
  FPM_JUMP_LINEAR = 0, /* each point's linear field (the FPM paper) */
  FPM_JUMP_QUADRATIC   /* a least-squares quadratic fit about each point */
} fpm_jump;

/* The volumetric part of the stress. */
typedef enum {
  FPM_VOLUMETRIC_STANDARD = 0, /* U'(J_i) of each point's own J */
  FPM_VOLUMETRIC_AVERAGED      /* J averaged over each point's support (F-bar
                                  kind; fpm_volumetric.h) */
} fpm_volumetric;

/* A named set of defaults for the flux keys. */
typedef enum {
  FPM_FORMULATION_DEFAULT = 0, /* accurate and stable: quadratic jump, small
                                  p, averaged volume where it applies */
  FPM_FORMULATION_PAPER        /* the FPM paper's: linear jump, p = 20,
                                  standard volume */
} fpm_formulation;

/* fpm.stiffening_spacing: the spacing the stiffening's onset is measured
 * in: the points' reference distance, or their current (deformed) one. */
typedef enum { FPM_SPACING_REFERENCE = 0, FPM_SPACING_CURRENT } fpm_spacing;

/* Options of the fpm section. */
typedef struct {
  int formulation;         /* fpm_formulation */
  double penalty;          /* fpm.penalty p >= 0 (beta = p E / h) */
  double boundary_penalty; /* fpm.boundary_penalty p_b >= 0: linear-jump
                              penalty on boundary interfaces (quadratic jump) */
  double stiffening;       /* fpm.stiffening p_s >= 0: quartic penalty on
                              the linear jump, |e| p_s E/h^3 |[[u]]|^4 / 4 */
  int stiffening_jump;     /* fpm.stiffening_jump: the fpm_jump it measures */
  double stiffening_onset; /* fpm.stiffening_onset tau >= 0: the stiffening
                              acts on |[[u]]|^2 - (tau h)^2 beyond it */
  int stiffening_spacing;  /* fpm.stiffening_spacing: fpm_spacing, the h of
                              the onset (reference or current) */
  double volume_penalty;   /* fpm.volume_penalty p_v >= 0: linear-jump
                              penalty p_v E / h (ln J)^2 */
  int flux;                /* fpm_flux */
  int jump;                /* fpm_jump */
  int volumetric;          /* fpm_volumetric */
  char *cells;             /* fpm.cells: the partition into subdomains */
} fpm_options;

extern const pm_section fpm_section;

/* The fpm options of a scene (its defaults when the scene has none). */
const fpm_options *fpm_scene_options(const pm_scene *s);

/* What FPM cannot honour (fluids, initial velocities, gravity, grid
 * conditions, ...), failing at the key with pm_scene_fail. */
pm_err fpm_check_scene(const pm_scene *s);

#endif
