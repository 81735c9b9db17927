// Box [0,2]x[0,1]x[0,1] in 4x2x2 linear hexahedra, by extrusion (mica test mesh). Sets: left (x=0),
// right (x=2), bottom (y=0), top (y=1), back (z=0), front (z=1); volume "box".
// Regenerate: gmsh -3 -format msh41 box_hex.geo -o box_hex.msh
Point(1) = {0, 0, 0}; Point(2) = {2, 0, 0}; Point(3) = {2, 1, 0}; Point(4) = {0, 1, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = 5;
Transfinite Curve{2, 4} = 3;
Transfinite Surface{1};
Recombine Surface{1};
out[] = Extrude {0, 0, 1} { Surface{1}; Layers{2}; Recombine; };
// out[0] = top (z=1), out[1] = volume, out[2..5] = sides extruded from lines 1..4
Physical Surface("back") = {1};
Physical Surface("front") = {out[0]};
Physical Surface("bottom") = {out[2]};
Physical Surface("right") = {out[3]};
Physical Surface("top") = {out[4]};
Physical Surface("left") = {out[5]};
Physical Volume("box") = {out[1]};
Mesh.MshFileVersion = 4.1;
