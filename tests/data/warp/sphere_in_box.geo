// A sphere cut out of a box: the volume mesh of the warp cross-check against scipy
// (tests/volume/warp_sphere.py). The sphere's surface moves, the box stays.
SetFactory("OpenCASCADE");
Box(1) = {-1, -1, -1, 2, 2, 2};
Sphere(2) = {0, 0, 0, 0.4};
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
// sizes at the points: coarser on the box corners than on the sphere
sphere() = Surface In BoundingBox{-0.41, -0.41, -0.41, 0.41, 0.41, 0.41};
MeshSize{ PointsOf{ Volume{3}; } } = 0.18;
MeshSize{ PointsOf{ Surface{sphere()}; } } = 0.07;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm3D = 1;
