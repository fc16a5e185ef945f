// Constants shared by the kernel, its tables and every backend (GLSL subset, see glsl.hpp).

// What ended a ray: the `hit` AOV of DESIGN.md section 4. An object index is >= 0.
KCONST int kHitMiss = -1;
KCONST int kHitEscape = -2;
KCONST int kHitWall = -3;
KCONST int kHitFloor = -4;
KCONST int kHitMaxSteps = -5;
KCONST int kHitMaxDistance = -6;
KCONST int kHitVertex = -7;

// Methods of DESIGN.md section 3 that the kernel runs.
KCONST int kMethodSphere = 0;
KCONST int kMethodRelaxed = 1;
KCONST int kMethodAnalytic = 2;

// What an edge does to a ray that reaches it.
KCONST int kEdgeGlued = 0;
KCONST int kEdgeMirror = 1;
KCONST int kEdgeWall = 2;

// Solids of the object table; vertex markers are cylinders.
KCONST int kSolidSphere = 0;
KCONST int kSolidBox = 1;
KCONST int kSolidHollowCube = 2;
KCONST int kSolidCylinder = 3;

// Transport events, numbered as flatmarch::EventKind.
KCONST int kEventGluing = 0;
KCONST int kEventMirror = 1;
KCONST int kEventEnter = 2;
KCONST int kEventObject = 3;
KCONST int kEventWall = 4;
KCONST int kEventFloor = 5;
KCONST int kEventEscape = 6;
KCONST int kEventVertex = 7;
KCONST int kEventMaxSteps = 8;
KCONST int kEventMaxDistance = 9;
KCONST int kEventMiss = 10;

// Features a scene may use. The kernel is specialised on the set a scene uses, so code for the
// others is not there at all (a template parameter in C++, a constant in a shader).
KCONST uint kFeatureObjects = 1u;  // objects or vertex markers
KCONST uint kFeatureMirrors = 2u;
KCONST uint kFeatureWalls = 4u;
KCONST uint kFeaturePeriod = 8u;   // translation prism: z modulo the period
KCONST uint kFeatureFloor = 16u;
KCONST uint kFeatureScaled = 32u;  // a gluing that is not an isometry: renormalise directions
KCONST uint kFeatureCount = 64u;   // number of feature sets

// A distance no ray reaches.
KCONST float kFar = 1e30f;

// Appearance: opaque walls are light grey; the floor alternates it with a darker grey in
// checks of this side.
KCONST float kWallGrey = 0.8f;
KCONST float kFloorDarkGrey = 0.55f;
KCONST float kFloorCheck = 0.5f;
