// A 40 x 30 x 20 box, every edge filleted (radius 4: 12 cylinders, 8 sphere corners), drilled through (radius 6).
// Built with Debian's gmsh (OpenCASCADE kernel): gmsh -0 fbox.geo writes fbox.step (docs/benchmarks.md, "Revolution shortcut").
SetFactory("OpenCASCADE");
Box(1) = {0,0,0, 40,30,20};
f() = Fillet{1}{1,2,3,4,5,6,7,8,9,10,11,12}{4};
Cylinder(10) = {20,15,-5, 0,0,40, 6};
BooleanDifference(20) = { Volume{f()}; Delete; }{ Volume{10}; Delete; };
Save "fbox.step";
