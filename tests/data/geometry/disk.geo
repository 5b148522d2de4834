// A disk of radius 0.5 in the z = 0 plane, its rim a named curve.
SetFactory("OpenCASCADE");
Disk(1) = {0, 0, 0, 0.5};
Physical Curve("rim") = {1};
Physical Surface("disk") = {1};
