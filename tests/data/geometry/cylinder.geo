// A cylinder of radius 0.05 and height 0.1 standing on z = 0, with its end
// faces named and its lateral surface left without a group.
SetFactory("OpenCASCADE");
Cylinder(1) = {0, 0, 0, 0, 0, 0.1, 0.05};
eps = 1e-6;
bottom() = Surface In BoundingBox{-1, -1, -eps, 1, 1, eps};
top() = Surface In BoundingBox{-1, -1, 0.1 - eps, 1, 1, 0.1 + eps};
Physical Surface("bottom") = {bottom()};
Physical Surface("top") = {top()};
Physical Volume("body") = {1};
