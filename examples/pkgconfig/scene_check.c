/* scene-check: a scene given as a string, checked by pointmech.h without a
 * run; built with pkg-config:
 *   cc scene_check.c $(pkg-config --cflags --libs pointmech)
 * Prints the library's version, the scene's method, and the message a bad
 * override gets (its key and the value expected). */
#include <stdio.h>

#include <pointmech.h>

static const char scene[] =
    "name: block\n"
    "method: fpm\n"
    "dimension: 2\n"
    "domain: {box: {min: [0, 0], max: [1, 1]}}\n"
    "discretization: {mesh_size: 0.25}\n"
    "materials: [{name: m, model: neo-hookean, density: 1000, "
    "youngs_modulus: 1e4, poisson_ratio: 0.3}]\n"
    "bodies: [{material: m, region: domain}]\n"
    "time: {end: 0.1}\n";

int main(void) {
  printf("pointmech %s\n", pointmech_version());
  pointmech *p = NULL;
  pointmech_code c = pointmech_create(&p);
  if (!c) c = pointmech_load_string(p, scene, "block.yaml");
  if (c) {
    fprintf(stderr, "%s: %s\n", pointmech_code_name(c),
            pointmech_error_message());
    return 1;
  }
  printf("%s: %s\n", pointmech_scene_name(p), pointmech_method(p));
  pointmech_destroy(p);

  /* A bad value is refused at load, naming the key. */
  c = pointmech_create(&p);
  if (!c) c = pointmech_set(p, "time.end=-1");
  if (!c) c = pointmech_load_string(p, scene, "block.yaml");
  printf("%s: %s\n", pointmech_code_name(c), pointmech_error_message());
  pointmech_destroy(p);
  return c == POINTMECH_ERR_SCENE ? 0 : 1;
}
