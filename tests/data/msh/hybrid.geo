// Hex, prism, pyramid and tet cells in one mesh (built-in kernel): a transfinite recombined
// box (hexes), an extruded triangle layer (prisms) and a tet box glued to a quad face
// (gmsh inserts pyramids there).
h = 0.5;
Point(1) = {0, 0, 0, h}; Point(2) = {1, 0, 0, h}; Point(3) = {1, 1, 0, h}; Point(4) = {0, 1, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Transfinite Curve{1, 2, 3, 4} = 3; Transfinite Surface{1}; Recombine Surface{1};
hex[] = Extrude{0, 0, 1}{ Surface{1}; Layers{2}; Recombine; };
Point(105) = {2, 0, 0, h}; Point(106) = {2, 1, 0, h};
Line(105) = {2, 105}; Line(106) = {105, 106}; Line(107) = {106, 3};
Curve Loop(102) = {105, 106, 107, -2}; Plane Surface(102) = {102};
pri[] = Extrude{0, 0, 1}{ Surface{102}; Layers{2}; Recombine; };
// tet box on top of the hex box: its bottom face is the hexes' quad top face
top = hex[0];
tet[] = Extrude{0, 0, 1}{ Surface{top}; };
Physical Volume("hex", 1) = {hex[1]};
Physical Volume("prism", 2) = {pri[1]};
Physical Volume("tet", 3) = {tet[1]};
Physical Surface("bottom", 4) = {1, 102};
