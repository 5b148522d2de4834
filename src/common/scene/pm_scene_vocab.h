/* pm_scene_vocab: the shared keys of a scene and the checks across them.
 * Private to the scene loader. */
#ifndef PM_SCENE_VOCAB_H
#define PM_SCENE_VOCAB_H

#include "pm_reader.h"
#include "pm_scene.h"

/* The top-level keys every method shares. */
extern const pm_key pm_scene_keys[];

/* After reading: defaults that depend on other keys, names resolved to
 * indices, and the checks across keys, each failing at the key at fault. */
pm_err pm_scene_finish(pm_reader *r, pm_scene *s);

#endif
