// Unit square in 4x4 linear quadrangles with no physical groups (mica test mesh): Gmsh saves every element,
// and mica has no boundary set to put a condition on; its error says how to add a physical group.
// Regenerate: gmsh -2 -format msh41 square_nophys.geo -o square_nophys.msh
Point(1) = {0, 0, 0}; Point(2) = {1, 0, 0}; Point(3) = {1, 1, 0}; Point(4) = {0, 1, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 2, 3, 4} = 5;
Transfinite Surface{1};
Recombine Surface{1};
