// A block [0, 0.2] x [0, 0.1] x [0, 0.05] whose whole boundary is in
// physical surfaces: named ends, named sides, and one face in a group
// without a name.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.2, 0.1, 0.05};
eps = 1e-6;
xmin() = Surface In BoundingBox{-eps, -1, -1, eps, 1, 1};
bottom() = Surface In BoundingBox{-1, -1, -eps, 1, 1, eps};
top() = Surface In BoundingBox{-1, -1, 0.05 - eps, 1, 1, 0.05 + eps};
all() = Surface{:};
Physical Surface("bottom") = {bottom()};
Physical Surface("top") = {top()};
Physical Surface("sides") = {all()};
Physical Surface("sides") -= {bottom(), top(), xmin()};
Physical Surface(17) = {xmin()};
Physical Volume("body") = {1};
