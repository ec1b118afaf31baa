// A flange (radius 30, 10 thick) under a pipe (radius 12, 40 long), bored through (radius 8), six bolt holes (radius 3) on a circle of radius 20.
// Built with Debian's gmsh (OpenCASCADE kernel): gmsh -0 flange.geo writes flange.step (docs/benchmarks.md, "Revolution shortcut").
SetFactory("OpenCASCADE");
Cylinder(1) = {0,0,0, 0,0,10, 30};
Cylinder(2) = {0,0,10, 0,0,40, 12};
BooleanUnion(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Cylinder(4) = {0,0,-5, 0,0,60, 8};
BooleanDifference(5) = { Volume{3}; Delete; }{ Volume{4}; Delete; };
For i In {0:5}
  Cylinder(10+i) = {20*Cos(i*Pi/3), 20*Sin(i*Pi/3), -5, 0,0,20, 3};
EndFor
BooleanDifference(30) = { Volume{5}; Delete; }{ Volume{10:15}; Delete; };
Save "flange.step";
