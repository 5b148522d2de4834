/* mpm_panel_testing: the user guide's tapered panel (coarse: cells of 1
 * m) for the MPM tests of loads and conditions on its named edges:
 * clamped on the face xmin, a traction on the named edge tip. */
#ifndef MPM_PANEL_TESTING_H
#define MPM_PANEL_TESTING_H

#include "pm_testing.h"

static const char *const GEO =
    "lc = 1;\n"
    "Point(1) = {0, 0, 0, lc}; Point(2) = {10, 1, 0, lc};\n"
    "Point(3) = {10, 3, 0, lc}; Point(4) = {0, 4, 0, lc};\n"
    "Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};\n"
    "Curve Loop(1) = {1, 2, 3, 4};\nPlane Surface(1) = {1};\n"
    "Physical Curve(\"clamped\") = {4};\nPhysical Curve(\"tip\") = {2};\n"
    "Physical Surface(\"panel\") = {1};\n";

static const char *const SCENE =
    "name: panel\nmethod: mpm-implicit\ndimension: 2\n"
    "domain: {box: {min: [0, 0], max: [10, 4]}}\n"
    "discretization: {mesh_size: 1}\n"
    "mpm: {fbar: none}\n"
    "materials:\n  - {name: gel, model: neo-hookean, density: 1000, "
    "youngs_modulus: 3000, poisson_ratio: 0.45}\n"
    "bodies: [{material: gel, mesh: panel.geo}]\n"
    "boundary:\n  - {on: xmin, displacement: {x: 0, y: 0}}\n"
    "  - {on: tip, traction: {x: 2, y: 10}, ramp: smooth}\n"
    "time: {end: 1, quasi_static: {method: static, load_steps: 10}}\n";

static void write_panel(const char *dir, char path[512]) {
  pm_test_write_file(dir, "panel.geo", GEO, path);
  pm_test_write_file(dir, "panel.yaml", SCENE, path);
}

#endif
