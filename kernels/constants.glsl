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

// Appearance (DESIGN.md section 1): the floor's checks are this wide, the dark ones this share
// of the light ones; surfaces are lit by a light from this unit direction (above, from the
// side) and this much ambient light.
KCONST float kFloorCheck = 0.5f;
KCONST float kFloorDark = 0.42f;
KCONST float kFloorFade = 60.0f;  // t / |dz| at which the checks' contrast is halved
KCONST float kLightX = 0.35f;
KCONST float kLightY = 0.55f;
KCONST float kLightZ = 0.758288f;  // sqrt(1 - 0.35^2 - 0.55^2)
KCONST float kAmbient = 0.45f;
KCONST float kExposure = 0.8f;
