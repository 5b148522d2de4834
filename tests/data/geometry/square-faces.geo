// The rectangle gm_mesh_box meshes for [0, 0.1]^2, its edges named as
// gm_mesh_box names them (OpenCASCADE numbers a rectangle's edges ymin,
// xmax, ymax, xmin).
SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 0.1, 0.1};
Physical Curve("xmin") = {4};
Physical Curve("xmax") = {2};
Physical Curve("ymin") = {1};
Physical Curve("ymax") = {3};
