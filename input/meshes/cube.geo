// Unit cube [0,1]^3 in linear tetrahedra (mica shipped mesh). Boundary sets named like mica's box:
// left (x=0), right (x=1), bottom (y=0), top (y=1), back (z=0), front (z=1); the volume is "cube".
// Regenerate: gmsh -3 -format msh41 cube.geo -o cube.msh
SetFactory("OpenCASCADE");
h = 0.25; // element size
Box(1) = {0, 0, 0, 1, 1, 1};
MeshSize{ PointsOf{ Volume{1}; } } = h;
e = 1e-6;
Physical Surface("left") = Surface In BoundingBox{-e, -e, -e, e, 1 + e, 1 + e};
Physical Surface("right") = Surface In BoundingBox{1 - e, -e, -e, 1 + e, 1 + e, 1 + e};
Physical Surface("bottom") = Surface In BoundingBox{-e, -e, -e, 1 + e, e, 1 + e};
Physical Surface("top") = Surface In BoundingBox{-e, 1 - e, -e, 1 + e, 1 + e, 1 + e};
Physical Surface("back") = Surface In BoundingBox{-e, -e, -e, 1 + e, 1 + e, e};
Physical Surface("front") = Surface In BoundingBox{-e, -e, 1 - e, 1 + e, 1 + e, 1 + e};
Physical Volume("cube") = {1};

Mesh.MshFileVersion = 4.1;
Mesh.Binary = 0;
