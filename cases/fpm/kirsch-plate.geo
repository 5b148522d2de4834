// A quarter of a plate with a circular hole (radius a = 1 m) at the
// origin, out to L = 5 m: Kirsch's problem, with the exact stresses of the
// infinite plate as tractions on the outer edges (kirsch-plate.yaml).  The
// elements on the hole are four times finer than at the outer corner.
SetFactory("OpenCASCADE");
a = 1; L = 5; lc = 0.5;
Rectangle(1) = {0, 0, 0, L, L};
Disk(2) = {0, 0, 0, a};
BooleanDifference(3) = {Surface{1}; Delete;}{Surface{2}; Delete;};
eps = 1e-6;
left() = Curve In BoundingBox{-eps, -eps, -eps, eps, L + eps, eps};
bottom() = Curve In BoundingBox{-eps, -eps, -eps, L + eps, eps, eps};
right() = Curve In BoundingBox{L - eps, -eps, -eps, L + eps, L + eps, eps};
top() = Curve In BoundingBox{-eps, L - eps, -eps, L + eps, L + eps, eps};
hole() = Curve In BoundingBox{-eps, -eps, -eps, a + eps, a + eps, eps};
Physical Curve("left") = {left()};
Physical Curve("bottom") = {bottom()};
Physical Curve("right") = {right()};
Physical Curve("top") = {top()};
Physical Curve("hole") = {hole()};
Physical Surface("plate") = {3};
MeshSize{PointsOf{Curve{hole()};}} = lc / 4;
MeshSize{PointsOf{Curve{right()};}} = lc;
MeshSize{PointsOf{Curve{top()};}} = lc;
