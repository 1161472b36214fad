// Bore model at t = 0 (benchmarks issue): block 4 x 4 x 2 with a through-bore of radius 0.6
// along z at its centre. Meshed by gmsh for the demo and the CLI tests.
SetFactory("OpenCASCADE");
Box(1) = {-2, -2, 0, 4, 4, 2};
Cylinder(2) = {0, 0, -1, 0, 0, 4, 0.6};
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Physical Volume("block", 1) = {3};
Physical Surface("bore", 2) = {7};
Mesh.MeshSizeMax = 0.45;
Mesh.MeshSizeMin = 0.2;
