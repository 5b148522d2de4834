// A tapered plane-strain panel (10 m long, 4 m high at x = 0, 2 m at
// x = 10) whose corner at the origin asks for elements ten times smaller
// than the rest: a grading the scene's mesh size must keep.
lc = 0.5;
Point(1) = {0, 0, 0, lc / 10}; Point(2) = {10, 1, 0, lc};
Point(3) = {10, 3, 0, lc};     Point(4) = {0, 4, 0, lc};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("clamped") = {4};
Physical Curve("tip") = {2};
Physical Surface("panel") = {1};
