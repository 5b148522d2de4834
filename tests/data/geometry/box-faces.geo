// The box gm_mesh_box meshes for [0, 0.1]^3, its faces named as gm_mesh_box
// names them (OpenCASCADE numbers a box's faces xmin, xmax, ymin, ymax,
// zmin, zmax).
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.1, 0.1, 0.1};
Physical Surface("xmin") = {1};
Physical Surface("xmax") = {2};
Physical Surface("ymin") = {3};
Physical Surface("ymax") = {4};
Physical Surface("zmin") = {5};
Physical Surface("zmax") = {6};
