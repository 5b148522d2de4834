/* output_testing: what the tests of the results writer share (test_output,
 * test_output_surface): two tetrahedra over five points, a scene text,
 * counting text in an XDMF, and Python's XML parser over it.  Include after
 * cmocka.h and pm_testing.h. */
#ifndef OUTPUT_TESTING_H
#define OUTPUT_TESTING_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Two tetrahedra sharing a face. */
#define NP 5
#define NC 2
static const double coords[3 * NP] = {0, 0, 0, 1, 0, 0, 0, 1,
                                      0, 0, 0, 1, 1, 1, 1};
static const long tets[4 * NC] = {0, 1, 2, 3, 1, 2, 3, 4};
static const char *scene = "name: \"two tets\"\nmaterial: {E: 1e9}\n";

/* Occurrences of needle in text[from, to). */
static inline int count_in(const char *from, const char *to,
                           const char *needle) {
  int n = 0;
  for (const char *p = strstr(from, needle); p && p < to;
       p = strstr(p + 1, needle))
    n++;
  return n;
}

/* Python's own XML parser reads dir/results.xdmf (root element x) and
 * asserts check, when /usr/bin/python3 is installed. */
static inline void python_check_xdmf(const char *dir, const char *check) {
  char cmd[2048];
  if (access("/usr/bin/python3", X_OK) != 0) return;
  snprintf(cmd, sizeof cmd,
           "/usr/bin/python3 -c 'import sys, xml.etree.ElementTree as E; "
           "x = E.parse(sys.argv[1]).getroot(); assert %s' %s/results.xdmf",
           check, dir);
  assert_int_equal(system(cmd), 0);
}

#endif
