// Box with a cylindrical hole; physical groups on the solid, the hole wall and the box sides.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 2, 1, 1};
Cylinder(2) = {1, 0.5, -0.1, 0, 0, 1.2, 0.25};
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Mesh.MeshSizeMax = 0.55;
Mesh.MeshSizeMin = 0.3;
Mesh.MeshSizeFromCurvature = 0;
Physical Volume("solid", 10) = {3};
hole() = Surface In BoundingBox{0.7, 0.2, -0.01, 1.3, 0.8, 1.01};
Physical Surface("hole", 20) = {hole()};
Physical Surface("left", 21) = Surface In BoundingBox{-0.01, -0.01, -0.01, 0.01, 1.01, 1.01};
