// A quarter of a thick ring, inner radius 1 m, outer 2 m
lc = 0.1;
Point(1) = {0, 0, 0, lc}; Point(2) = {1, 0, 0, lc}; Point(3) = {2, 0, 0, lc};
Point(4) = {0, 2, 0, lc}; Point(5) = {0, 1, 0, lc};
Line(1) = {2, 3}; Circle(2) = {3, 1, 4}; Line(3) = {4, 5}; Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("ysym") = {1};
Physical Curve("outer") = {2};
Physical Curve("xsym") = {3};
Physical Curve("inner") = {4};
Physical Surface("ring") = {1};
