// Quarter plate with a hole (mica shipped mesh): [0,5]x[0,5] minus the disk r < 1 at the origin.
// Linear triangles, refined towards the hole. Boundary sets: hole, left (x=0), bottom (y=0),
// right (x=5), top (y=5); the plate surface is the physical group "plate".
// Regenerate: gmsh -2 -format msh41 plate_hole.geo -o plate_hole.msh
a = 1.0;      // hole radius
b = 5.0;      // plate size
h_hole = 0.1; // element size at the hole
h_out = 0.5;  // element size at the outer corner

Point(1) = {0, 0, 0, h_hole};
Point(2) = {a, 0, 0, h_hole};
Point(3) = {b, 0, 0, h_out};
Point(4) = {b, b, 0, h_out};
Point(5) = {0, b, 0, h_out};
Point(6) = {0, a, 0, h_hole};

Line(1) = {2, 3};        // bottom
Line(2) = {3, 4};        // right
Line(3) = {4, 5};        // top
Line(4) = {5, 6};        // left
Circle(5) = {6, 1, 2};   // hole
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};

Physical Curve("hole") = {5};
Physical Curve("left") = {4};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Surface("plate") = {1};

Mesh.MshFileVersion = 4.1;
Mesh.Binary = 0;
