// A ball of radius 0.5 about (1, 2, 3).
SetFactory("OpenCASCADE");
Sphere(1) = {1, 2, 3, 0.5};
