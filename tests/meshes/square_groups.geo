// Unit square in 4x4 linear quadrangles whose entities are in several physical groups (mica test mesh):
// curve 4 is in "left" and "sides", curve 2 in "right" and "sides", the surface in "square" and "again".
// A 2.2 file lists such elements once per group; mica must merge the copies (one area, not two).
// Regenerate: gmsh -2 -format msh41 square_groups.geo -o square_groups.msh
//             gmsh -2 -format msh22 square_groups.geo -o square_groups_v22.msh
Point(1) = {0, 0, 0}; Point(2) = {1, 0, 0}; Point(3) = {1, 1, 0}; Point(4) = {0, 1, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 2, 3, 4} = 5;
Transfinite Surface{1};
Recombine Surface{1};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Curve("sides") = {2, 4};
Physical Surface("square") = {1};
Physical Surface("again") = {1};
