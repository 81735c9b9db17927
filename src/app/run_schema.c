/* The deck of `mica run`, `mica check`, `mica sweep` and `mica study`: every setting, its type, default, range and
 * meaning (docs/input.md is generated from `mica help run`). A run deck may carry a `sweep`
 * group: `mica run` and `mica check` solve or size the deck as it stands and leave the group alone,
 * `mica sweep` runs it over the group's values; likewise the `study` group and `mica study`. One schema, so
 * one deck serves all four. */
#include "run.h"
#include "sweep.h"

MICA_SCHEMA_TABLES

#define NOLIMIT 1.0, 0.0

/* The values of one varied setting, the same for a sweep's parameters and a study's choices (one list element,
 * read by sweep_spec.c: sweep_axis_read). */
static const MicaDeckKey varied_values[] = {
    {"values", MICA_KEY_FLOATS, NULL, NOLIMIT, NULL, 1, 0, "its values: numbers, or expressions of the deck's parameters"},
    {"words", MICA_KEY_STRING, NULL, NOLIMIT, NULL, 0, MICA_DECK_LONG_TEXT_MAX,
     "... or, for a string setting, its values as words: \"linear, svk\""},
    {"range", MICA_KEY_FLOATS, NULL, NOLIMIT, NULL, 2, 2, "... or the first and last of `points` values spaced by `scale`"},
    {"points", MICA_KEY_INT, NULL, 2, SWEEP_LIMIT_MOST, NULL, 0, 0, "number of values of a range"},
    {"scale", MICA_KEY_CHOICE, "\"linear\"", NOLIMIT, "linear|log", 0, 0,
     "spacing of a range: equal differences or equal ratios"},
    {NULL},
};

/* The mls.* settings are the same as `mica mls`'s, with solid-mechanics defaults. */
const MicaDeckKey mica_run_schema[] = {
    {"parameters", MICA_KEY_PARAMETERS, NULL, NOLIMIT, NULL, 0, 0,
     "named numbers (or expressions of earlier ones) usable in any numeric setting and expression"},
    {"problem.title", MICA_KEY_STRING, "\"\"", NOLIMIT, NULL, 0, 0, "a title for the summary"},
    {.path = "problem.method", .type = MICA_KEY_CHOICE, .min = 1.0, .max = 0.0, .registry = &mica_approx_registry,
     .help = "the approximation: efg (MLS shape functions, background-cell quadrature) or fe, the finite-element "
             "baseline: Lagrange elements of order mls.order (1: Q1 / hex8, 2: Q2 / hex27) with the particles of a "
             "regular, graded or jittered layout of a built-in shape as nodes, quadrature.order Gauss points per "
             "direction per element"},
    {"geometry.shape", MICA_KEY_CHOICE, "\"box\"", NOLIMIT, "box|polygon|plate_hole|annulus|cylinder|gmsh", 0, 0,
     "the body: a built-in shape or a Gmsh mesh"},
    {"geometry.lower", MICA_KEY_FLOATS, NULL, NOLIMIT, NULL, 2, 3, "box: lower corner (its length sets the dimension)"},
    {"geometry.upper", MICA_KEY_FLOATS, NULL, NOLIMIT, NULL, 2, 3, "box: upper corner"},
    {"geometry.vertices", MICA_KEY_FLOATS, NULL, NOLIMIT, NULL, 8, 8,
     "polygon: x0, y0, ..., x3, y3 of a convex quadrilateral, counterclockwise"},
    {"geometry.hole_radius", MICA_KEY_FLOAT, NULL, 1e-12, 1e12, NULL, 0, 0, "plate_hole: radius a of the hole"},
    {"geometry.plate_size", MICA_KEY_FLOATS, NULL, 1e-12, 1e12, NULL, 2, 2, "plate_hole: the quarter plate's width and height"},
    {"geometry.r_inner", MICA_KEY_FLOAT, NULL, 0, 1e12, NULL, 0, 0, "annulus: inner radius"},
    {"geometry.r_outer", MICA_KEY_FLOAT, NULL, 1e-12, 1e12, NULL, 0, 0, "annulus: outer radius"},
    {"geometry.angles", MICA_KEY_FLOATS, "[0.0, 90.0]", -360, 360, NULL, 2, 2, "annulus: first and last angle, degrees"},
    {"geometry.radius", MICA_KEY_FLOAT, NULL, 1e-12, 1e12, NULL, 0, 0, "cylinder: radius (axis along z)"},
    {"geometry.height", MICA_KEY_FLOAT, NULL, 1e-12, 1e12, NULL, 0, 0, "cylinder: height"},
    {"geometry.mesh", MICA_KEY_STRING, NULL, NOLIMIT, NULL, 0, MICA_DECK_LONG_TEXT_MAX,
     "gmsh: a Gmsh mesh, .msh 4.1 (ASCII or binary) or 2.2 (ASCII), or a .geo that mica meshes with the Gmsh "
     "library in its own dimension; relative to the deck's directory"},
    {"geometry.mesh_size_factor", MICA_KEY_FLOAT, NULL, 1e-3, 1e3, NULL, 0, 0,
     "gmsh with a .geo: multiplies its element sizes (Gmsh's Mesh.MeshSizeFactor, gmsh -clscale)"},
    {"geometry.axisymmetric", MICA_KEY_BOOL, "false", NOLIMIT, NULL, 0, 0,
     "2-D only: the section in x = r ≥ 0, y = z is revolved about the y axis; unknowns ur, utheta, uz (+ phir, "
     "phitheta, phiz), torsion included"},
    {"particles.layout", MICA_KEY_CHOICE, "\"regular\"", NOLIMIT, "regular|graded|jittered|irregular", 0, 0,
     "how particles are placed (in the shape's parameter space)"},
    {"particles.count", MICA_KEY_INTS, NULL, 2, 1e6, NULL, 2, 3, "particles per parameter axis"},
    {"particles.jitter", MICA_KEY_FLOAT, "0.2", 0, 0.45, NULL, 0, 0, "jittered: shift, as a fraction of the spacing"},
    {"particles.grading", MICA_KEY_FLOATS, "[1.0]", 1e-3, 1e3, NULL, 1, 3,
     "graded: ratio of the last spacing to the first, per axis (one value for all)"},
    {"particles.seed", MICA_KEY_INT, "1", 0, 2147483647, NULL, 0, 0, "seed of the jittered and irregular layouts"},
    {.path = "mls", .type = MICA_KEY_FRAGMENT, .fragment = mls_keys}, /* src/mls/settings.c */
    {"quadrature.order", MICA_KEY_INT, "4", 1, 20, NULL, 0, 0, "Gauss points per direction in each background cell"},
    {"quadrature.boundary_order", MICA_KEY_INT, "0", 0, 20, NULL, 0, 0,
     "Gauss points per direction on boundary edges/faces (0: quadrature.order)"},
    {"quadrature.error_order", MICA_KEY_INT, "0", 0, 20, NULL, 0, 0,
     "Gauss points per direction in each background cell for the error norms only (0: the solve's points), so "
     "that the error measure does not change with quadrature.order"},
    {"quadrature.vci", MICA_KEY_BOOL, "\"auto\"", NOLIMIT, "auto", 0, 0,
     "variationally consistent integration: corrected test gradients pass the patch test of the basis order "
     "(first-order models; unsymmetric tangent: UMFPACK). auto: on for jittered, irregular and Gmsh particles, "
     "off on regular and graded grids and where VCI does not apply (the run says which and why)"},
    {.path = "quadrature.mode", .type = MICA_KEY_CHOICE, .min = 1.0, .max = 0.0, .registry = &run_integration_registry,
     .help = "gauss: Gauss points of the background cells; nodal: direct nodal integration at the particles, "
     "weighted by their nodal cells' volumes (fails the patch test, a low-energy mode on the free block; shown, not cured); scni: stabilized "
     "conforming nodal integration, smoothed gradients on the nodal cells (passes the linear patch test; "
     "first-order models); nsni: naturally stabilized nodal integration, one point per particle plus the strain's "
     "gradient terms from the MLS Hessians, with VCI (auto) of the basis order: the production nodal mode (passes "
     "the linear and quadratic patch tests, no low-energy modes; first-order models). nodal, scni and nsni need a built-in shape with a regular, graded or jittered layout; error "
     "norms stay on the background Gauss points"},
    {"quadrature.cells", MICA_KEY_INTS, NULL, 1, 1e6, NULL, 2, 3,
     "background cells per parameter axis (default: particles.count − 1; other counts are placed along the particle lines, so k (count − 1) splits every spacing in k and a graded layout stays graded)"},
    {.path = "material.model", .type = MICA_KEY_CHOICE, .min = 1.0, .max = 0.0,
     .registry = &mica_field_model_registry,
     .help = "continuum model (docs/theory.md §models): a classical model (E, nu), or a field model of generalized "
             "kinematics"},
    {.path = "material.pressure", .type = MICA_KEY_CHOICE, .min = 1.0, .max = 0.0, .registry = &mica_pressure_registry,
     .help = "the pressure space of a classical solid (docs/theory.md §Nearly incompressible solids): none (the "
             "displacement form) or cell-constant (a pressure per background cell, condensed: B-bar / F-bar with the "
             "cell's mean dilatation; locking-free as ν → 0.5)"},
    {.path = "material.micro_model", .type = MICA_KEY_CHOICE, .def = "\"svk\"", .min = 1.0, .max = 0.0,
     .registry = &mica_model_registry,
     .help = "micromorph: the micro energy ψ (a classical model with material.E, material.nu)"},
    {"material.micro_kind", MICA_KEY_CHOICE, "\"F\"", NOLIMIT, "F|isochoric|rotation", 0, 0,
     "micromorph: the micro deformation χ: F (orientation, micro-shear and micro-stretch), isochoric (J^(−1/3) F: no micro volume change), rotation (R(Φ), an independent rotation field: unknowns u and φ; coupling number material.N)"},
    {"material.micro_axes", MICA_KEY_STRING, "\"\"", NOLIMIT, NULL, 0, 0,
     "micromorph: the micro space's axes, e.g. \"y\" (a line across a beam's thickness), \"xy\"; \"\": 0-D (classical)"},
    {"material.micro_sizes", MICA_KEY_FLOATS, NULL, NOLIMIT, NULL, 1, 3, "micromorph: the micro space's size along each axis"},
    {"material.E", MICA_KEY_FLOAT, NULL, NOLIMIT, NULL, 0, 0, "Young's modulus (classical models)"},
    {"material.nu", MICA_KEY_FLOAT, NULL, NOLIMIT, NULL, 0, 0, "Poisson's ratio (classical models; cosserat technical constants)"},
    {"material.G", MICA_KEY_FLOAT, NULL, NOLIMIT, NULL, 0, 0, "cosserat, technical constants: shear modulus G = μ + κ/2"},
    {"material.N", MICA_KEY_FLOAT, NULL, NOLIMIT, NULL, 0, 0, "cosserat, technical, and micromorph with micro_kind = rotation: coupling number N ∈ [0, 1)"},
    {"material.l", MICA_KEY_FLOAT, NULL, NOLIMIT, NULL, 0, 0, "length scale: cosserat (technical, 2-D), strain-gradient, couple-stress"},
    {"material.l_t", MICA_KEY_FLOAT, NULL, NOLIMIT, NULL, 0, 0, "cosserat, technical (3-D): torsion length l_t"},
    {"material.l_b", MICA_KEY_FLOAT, NULL, NOLIMIT, NULL, 0, 0, "cosserat, technical (3-D): bending length l_b"},
    {"material.psi", MICA_KEY_FLOAT, NULL, NOLIMIT, NULL, 0, 0, "cosserat, technical (3-D): polar ratio Ψ ∈ (0, 1.5]"},
    {"material.lambda", MICA_KEY_FLOAT, NULL, NOLIMIT, NULL, 0, 0, "cosserat, Eringen constants: λ"},
    {"material.mu", MICA_KEY_FLOAT, NULL, NOLIMIT, NULL, 0, 0, "cosserat, Eringen: μ"},
    {"material.kappa", MICA_KEY_FLOAT, NULL, NOLIMIT, NULL, 0, 0, "cosserat, Eringen: κ"},
    {"material.alpha", MICA_KEY_FLOAT, "0.0", NOLIMIT, NULL, 0, 0, "cosserat, Eringen (3-D): α"},
    {"material.beta", MICA_KEY_FLOAT, "0.0", NOLIMIT, NULL, 0, 0, "cosserat, Eringen (3-D): β"},
    {"material.gamma", MICA_KEY_FLOAT, NULL, NOLIMIT, NULL, 0, 0, "cosserat, Eringen: γ (the only couple modulus in 2-D)"},
    {"material.plane", MICA_KEY_CHOICE, "\"strain\"", NOLIMIT, "strain|stress", 0, 0,
     "2-D: plane strain or plane stress (plane stress: linear model only)"},
    {.path = "bc.method", .type = MICA_KEY_CHOICE, .min = 1.0, .max = 0.0, .registry = &mica_bc_method_registry,
     .help = "how Dirichlet conditions are imposed (docs/verification.md says why nitsche is the default)"},
    {"bcs.dirichlet", MICA_KEY_LIST, NULL, NOLIMIT, NULL, 0, 0,
     "prescribed displacements: ( { set = \"left\"; ux = \"0\"; uy = \"0\"; }, ... ); omitted components are free"},
    {"bcs.dirichlet.[].set", MICA_KEY_STRING, NULL, NOLIMIT, NULL, 0, 0, "boundary set name"},
    {"bcs.dirichlet.[].ux", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "prescribed u_x(x, y, z, t)"},
    {"bcs.dirichlet.[].uy", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "prescribed u_y"},
    {"bcs.dirichlet.[].uz", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "prescribed u_z"},
    {"bcs.dirichlet.[].phix", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "cosserat (3-D): prescribed micro-rotation φ_x"},
    {"bcs.dirichlet.[].phiy", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "cosserat (3-D): prescribed φ_y"},
    {"bcs.dirichlet.[].phiz", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "cosserat: prescribed φ_z (2-D: the micro-rotation)"},
    {"bcs.dirichlet.[].ur", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "axisymmetric: prescribed u_r"},
    {"bcs.dirichlet.[].utheta", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "axisymmetric: prescribed u_θ (torsion)"},
    {"bcs.dirichlet.[].phir", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "axisymmetric cosserat: prescribed φ_r"},
    {"bcs.dirichlet.[].phitheta", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "axisymmetric cosserat: prescribed φ_θ"},
    {"bcs.traction", MICA_KEY_LIST, NULL, NOLIMIT, NULL, 0, 0,
     "dead tractions per unit reference length/area: ( { set = \"right\"; ty = \"-P/D\"; }, ... )"},
    {"bcs.traction.[].set", MICA_KEY_STRING, NULL, NOLIMIT, NULL, 0, 0, "boundary set name"},
    {"bcs.traction.[].tx", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "traction t_x(x, y, z, t)"},
    {"bcs.traction.[].ty", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "traction t_y"},
    {"bcs.traction.[].tz", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "traction t_z"},
    {"bcs.traction.[].mx", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "cosserat (3-D): couple traction m_x"},
    {"bcs.traction.[].my", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "cosserat (3-D): couple traction m_y"},
    {"bcs.traction.[].mz", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "cosserat: couple traction m_z"},
    {"bcs.traction.[].tr", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "axisymmetric: traction t_r"},
    {"bcs.traction.[].ttheta", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "axisymmetric: traction t_θ"},
    {"bcs.traction.[].mr", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "axisymmetric cosserat: couple traction m_r"},
    {"bcs.traction.[].mtheta", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "axisymmetric cosserat: couple traction m_θ"},
    {"loads.bx", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "body force per unit reference volume, x"},
    {"loads.by", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "body force, y"},
    {"loads.bz", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "body force, z"},
    {"loads.cx", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "cosserat (3-D): body couple, x"},
    {"loads.cy", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "cosserat (3-D): body couple, y"},
    {"loads.cz", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "cosserat: body couple, z (2-D: the only one)"},
    {"loads.br", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "axisymmetric: body force, r"},
    {"loads.btheta", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "axisymmetric: body force, θ"},
    {"loads.cr", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "axisymmetric cosserat: body couple, r"},
    {"loads.ctheta", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "axisymmetric cosserat: body couple, θ"},
    {.path = "solver.linear", .type = MICA_KEY_CHOICE, .def = "\"auto\"", .min = 1.0, .max = 0.0, .choices = "auto",
     .registry = &mica_linear_solver_registry,
     .help = "auto: in one process CHOLMOD for symmetric positive definite tangents, cholmod-sym for VCI's "
             "(CHOLMOD on the symmetric part, refined to solver.linear_rtol), UMFPACK otherwise, and UMFPACK for the "
             "rest of the run, with a note, when CHOLMOD's factorization or cholmod-sym's refinement fails; under "
             "mpirun petsc "
             "with its default method (MUMPS); petsc: PETSc's solvers on the tangent distributed over the ranks, "
             "also in one process (solver.petsc chooses the method: MUMPS, GAMG, hypre, or Schwarz / block Jacobi "
             "with CHOLMOD or UMFPACK subdomains; iterative ones for problems whose factor does not fit)"},
    {"parallel.data", MICA_KEY_CHOICE, "\"replicated\"", NOLIMIT, "replicated|distributed", 0, 0,
     "MPI runs: replicated — every rank builds all particles, the partition is METIS's and vectors are whole on "
     "every rank; distributed — each rank owns a block of a built-in shape's particle and cell index grids, or a "
     "box of a Gmsh mesh's particles and the elements whose centroids it holds, and keeps only those, its points "
     "and a ghost layer (solver.linear = \"petsc\" or \"auto\"; every boundary method, background-cell quadrature "
     "with or without VCI, the nodal modes with the rank's own nodal cells (a Gmsh mesh or an irregular layout: NSNI), axisymmetric "
     "sections, probes, error norms and every output; no FE)"},
    {"solver.linear_rtol", MICA_KEY_FLOAT, "1e-10", 0, 1, NULL, 0, 0, "petsc (its Krylov methods), cholmod-sym: the iterations stop at |r| ≤ linear_rtol |b|"},
    {"solver.linear_max_iterations", MICA_KEY_INT, "2000", 1, 1000000, NULL, 0, 0, "petsc (its Krylov methods), cholmod-sym: iterations per solve"},
    {"solver.steps", MICA_KEY_INT, "1", 1, 100000, NULL, 0, 0, "load steps; the load factor t goes from 1/steps to 1"},
    {"solver.max_iterations", MICA_KEY_INT, "25", 1, 1000, NULL, 0, 0, "Newton iterations per step"},
    {"solver.rtol", MICA_KEY_FLOAT, "1e-10", 0, 1, NULL, 0, 0, "converged when |R| ≤ rtol |R₀| of the step"},
    {"solver.atol", MICA_KEY_FLOAT, "0.0", 0, 1e300, NULL, 0, 0, "... or when |R| ≤ atol"},
    {"solver.line_search", MICA_KEY_BOOL, "false", NOLIMIT, NULL, 0, 0, "backtracking line search on |R|"},
    {"solver.max_cuts", MICA_KEY_INT, "8", 0, 60, NULL, 0, 0,
     "times a failing load step may be halved (not for a linear problem, whose tangent does not depend on the load)"},
    {"solver.ramp", MICA_KEY_BOOL, "true", NOLIMIT, NULL, 0, 0,
     "multiply every load and prescribed value by the load factor t"},
    {"exact.ux", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "exact u_x, for error norms and error fields"},
    {"exact.uy", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "exact u_y"},
    {"exact.uz", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "exact u_z"},
    {"exact.phix", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "exact φ_x (cosserat, 3-D)"},
    {"exact.phiy", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "exact φ_y (cosserat, 3-D)"},
    {"exact.phiz", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "exact φ_z (cosserat)"},
    {"exact.ur", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "axisymmetric: exact u_r"},
    {"exact.utheta", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "axisymmetric: exact u_θ"},
    {"exact.phir", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "axisymmetric cosserat: exact φ_r"},
    {"exact.phitheta", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0, "axisymmetric cosserat: exact φ_θ"},
    /* the output types' own settings, output.vtu, output.mesh, output.monitor, output.probes,
     * output.quadrature_fields, ...: each declared by its type (src/app/output_*.c, mica/output.h) */
    {.path = "output", .type = MICA_KEY_FRAGMENT, .min = 1.0, .max = 0.0, .registry = &mica_output_registry},
    /* the sweep (src/study/sweep*.c) */

    {"limits.memory_gb", MICA_KEY_FLOAT, NULL, 1e-3, 1e6, NULL, 0, 0,
     "the most memory a run may need, GB: a deck whose estimated peak (docs/performance.md §the cost estimate) is "
     "larger is refused before anything is allocated (default: this machine's physical memory; a larger value "
     "lets a run try beyond it)"},
    {"limits.mesh_mb", MICA_KEY_FLOAT, "2048", 1e-3, 1e7, NULL, 0, 0,
     "the largest geometry.mesh file read, MB (and it must be a regular file, not a device, pipe or directory)"},
    {"limits.sweep_points", MICA_KEY_INT, SWEEP_LIMIT_DEFAULT, 1, SWEEP_LIMIT_MOST, NULL, 0, 0,
     "the most points of a sweep's grid (each a solve); a larger grid, or one axis with more values, is refused "
     "before any point runs"},
    {"limits.study_combinations", MICA_KEY_INT, SWEEP_LIMIT_DEFAULT, 1, SWEEP_LIMIT_MOST, NULL, 0, 0,
     "the most combinations of a study (each a solve); more, or one choice with more values, are refused before "
     "any runs"},
    {"sweep.parameters", MICA_KEY_LIST, NULL, NOLIMIT, NULL, 1, 0,
     "the swept settings: ( { path = \"parameters.L\"; values = [4.0, 8.0]; }, ... ); any scalar setting of the run deck"},
    {"sweep.parameters.[].path", MICA_KEY_STRING, NULL, NOLIMIT, NULL, 0, 0,
     "the setting swept: \"parameters.L\", \"mls.dilation\", \"material.model\", ..."},
    {.path = "sweep.parameters.[]", .type = MICA_KEY_FRAGMENT, .fragment = varied_values},
    {"sweep.mode", MICA_KEY_CHOICE, "\"grid\"", NOLIMIT, "grid|zip", 0, 0,
     "grid: every combination of the values; zip: the i-th values together (equal numbers of values)"},
    {"sweep.probe", MICA_KEY_STRING, "\"\"", NOLIMIT, NULL, 0, 0,
     "the probe charted (an output.probes name; default: the first)"},
    {"sweep.x", MICA_KEY_STRING, "\"\"", NOLIMIT, NULL, 0, 0,
     "the swept path on the chart's x axis (default: the first numeric one); the other paths make the curves"},
    {"sweep.xlabel", MICA_KEY_STRING, "\"\"", NOLIMIT, NULL, 0, 0,
     "the chart's x-axis label, words with units: \"hole radius / length scale a/ℓ\" (default: \"parameter a over "
     "l\" for parameters.a_over_l, \"mls dilation\" for a setting: underscores and dots as spaces)"},
    {"sweep.ylabel", MICA_KEY_STRING, "\"\"", NOLIMIT, NULL, 0, 0,
     "the chart's y-axis label (default: the probe's name, underscores as spaces, and its field: \"tip uy (probe of "
     "uy)\")"},
    {"sweep.analytic", MICA_KEY_LIST, NULL, NOLIMIT, NULL, 0, 0,
     "reference curves: ( { name = \"beam\"; f = \"P*x^3/(3*E*I)\"; }, ... )"},
    {"sweep.analytic.[].name", MICA_KEY_STRING, NULL, NOLIMIT, NULL, 0, 0, "legend of the curve"},
    {"sweep.analytic.[].f", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0,
     "the curve as an expression of x (the swept x value) and the deck's parameters"},
    {"sweep.experiments", MICA_KEY_LIST, NULL, NOLIMIT, NULL, 0, 0,
     "measured points: ( { name = \"Lam et al. 2003\"; file = \"data/epoxy.csv\"; }, ... )"},
    {"sweep.experiments.[].name", MICA_KEY_STRING, NULL, NOLIMIT, NULL, 0, 0, "legend of the points"},
    {"sweep.experiments.[].file", MICA_KEY_STRING, NULL, NOLIMIT, NULL, 0, MICA_DECK_LONG_TEXT_MAX,
     "CSV of x,y rows (other lines are skipped), relative to the deck's directory"},
    {"sweep.logx", MICA_KEY_BOOL, "false", NOLIMIT, NULL, 0, 0, "logarithmic x axis"},
    {"sweep.logy", MICA_KEY_BOOL, "false", NOLIMIT, NULL, 0, 0, "logarithmic y axis (only positive values show)"},
    {"sweep.chart", MICA_KEY_BOOL, "true", NOLIMIT, NULL, 0, 0, "draw sweep.png and sweep.svg with gnuplot"},
    {"sweep.classical", MICA_KEY_STRING, "\"linear\"", NOLIMIT, NULL, 0, 0,
     "when material.model is swept: the model the others are compared with"},
    {"sweep.tolerance", MICA_KEY_FLOAT, "0.01", 0, 1e300, NULL, 0, 0,
     "... a model agrees with it where |probe / probe_classical - 1| <= tolerance"},
    {"sweep.ranks_per_point", MICA_KEY_INT, "1", 1, 1000000, NULL, 0, 0,
     "under mpirun -np P: ranks that solve each point together; the P ranks form P / ranks_per_point groups and "
     "point i goes to group i mod groups (it must divide P; P: every point distributed over every rank)"},
    {"sweep.threshold_steps", MICA_KEY_INT, "8", 0, 60, NULL, 0, 0,
     "... bisection steps narrowing each model's threshold between the sampled x values (each step solves the "
     "model and the classical one at the midpoint, for every combination of the other paths; 0: the sampled "
     "bracket only)"},
    {"sweep.threshold_rtol", MICA_KEY_FLOAT, "0.01", 1e-12, 1, NULL, 0, 0,
     "... bisection stops once the bracket is at most this fraction of its upper end wide"},
    /* speed against accuracy (src/study/study*.c) */
    {"study.choices", MICA_KEY_LIST, NULL, NOLIMIT, NULL, 1, 0,
     "the varied settings, every combination solved: ( { path = \"mls.order\"; values = [1, 2]; }, ... ); any "
     "scalar setting of the run deck or a parameter"},
    {"study.choices.[].path", MICA_KEY_STRING, NULL, NOLIMIT, NULL, 0, 0,
     "the setting: \"mls.order\", \"parameters.n\", \"quadrature.order\", \"bc.method\", ..."},
    {"study.choices.[].name", MICA_KEY_STRING, NULL, NOLIMIT, NULL, 0, 0,
     "its short name in labels (default: the parameter's name, or the path)"},
    {.path = "study.choices.[]", .type = MICA_KEY_FRAGMENT, .fragment = varied_values},
    {"study.error", MICA_KEY_STRING, "\"energy\"", NOLIMIT, NULL, 0, 0,
     "the error measured: energy, l2, h1 (relative norms against exact.*) or a probe's name (with reference)"},
    {"study.reference", MICA_KEY_FLOAT, NULL, NOLIMIT, NULL, 0, 0,
     "for a probe: its exact or overkill value; the error is |probe - reference| / |reference|"},
    {"study.target", MICA_KEY_FLOAT, "1e-3", 0, 1e300, NULL, 0, 0,
     "the error to reach: the summary names the fastest combination with error <= target"},
    {"study.time", MICA_KEY_CHOICE, "\"solve\"", NOLIMIT, "solve|total", 0, 0,
     "the time of the front and of the fastest: solve (assembly + factorization + solution) or total (every phase)"},
    {"study.repeat", MICA_KEY_INT, "1", 1, 100, NULL, 0, 0,
     "solves per combination; each phase's minimum time is kept (fairer on a shared machine)"},
    {"study.ranks_per_point", MICA_KEY_INT, "1", 1, 1000000, NULL, 0, 0,
     "under mpirun -np P: ranks that solve each combination together; P / ranks_per_point groups solve at once, "
     "combination i in group i mod groups (it must divide P), so the groups share the machine during the timings"},
    {"study.chart", MICA_KEY_BOOL, "true", NOLIMIT, NULL, 0, 0, "draw study_time.png and study_dofs.png (and .svg) with gnuplot"},
    /* the stability study (src/study/stability*.c): `mica run` and `mica sweep` leave the group alone */
    {"stability.eigen", MICA_KEY_BOOL, "true", NOLIMIT, NULL, 0, 0,
     "mica stability: eigenvalues of the tangent at u = 0 with the deck's conditions (zero, rigid, spurious modes)"},
    {"stability.patch", MICA_KEY_BOOL, "true", NOLIMIT, NULL, 0, 0,
     "mica stability: linear and quadratic patch tests on the deck's particles with its quadrature, bc.method, VCI"},
    {"stability.inf_sup", MICA_KEY_BOOL, "true", NOLIMIT, NULL, 0, 0,
     "mica stability: numerical inf-sup test (Chapelle–Bathe) of the displacement formulation over "
     "stability.inf_sup_counts"},
    {"stability.conditioning", MICA_KEY_BOOL, "true", NOLIMIT, NULL, 0, 0,
     "mica stability: 2-norm condition number of the MLS moment matrix at every volume quadrature point"},
    {"stability.solver", MICA_KEY_CHOICE, "\"dense\"", NOLIMIT, "dense|sparse|auto", 0, 0,
     "eigenvalues: dense (LAPACK, all of them, up to stability.dense_max_dofs unknowns), sparse (shift-invert "
     "subspace iteration on the CHOLMOD/UMFPACK factor: the stability.modes lowest), auto (dense when small enough)"},
    {"stability.dense_max_dofs", MICA_KEY_INT, "3000", 1, 100000, NULL, 0, 0,
     "the largest number of unknowns the dense eigensolver takes"},
    {"stability.modes", MICA_KEY_INT, "30", 1, 100000, NULL, 0, 0,
     "sparse: how many of the lowest eigenvalues are computed (more than the zero modes expected)"},
    {"stability.zero_tol", MICA_KEY_FLOAT, "1e-8", 0, 1, NULL, 0, 0,
     "an eigenvalue λ is a zero mode when |λ| ≤ zero_tol · λ_max (also for the inf-sup eigenvalues)"},
    {"stability.shift", MICA_KEY_FLOAT, "1e-6", 1e-14, 1, NULL, 0, 0,
     "sparse: K − σI is factored with σ = −shift · λ_max (below the spectrum: positive definite for a free body)"},
    {"stability.tol", MICA_KEY_FLOAT, "1e-10", 1e-15, 1e-2, NULL, 0, 0,
     "sparse: an eigenpair is converged when ‖K x − λ x‖ ≤ tol · λ_max"},
    {"stability.max_iterations", MICA_KEY_INT, "3000", 1, 1000000, NULL, 0, 0, "sparse: subspace iterations allowed"},
    {"stability.reference", MICA_KEY_CHOICE, "\"gauss\"", NOLIMIT, "gauss|none", 0, 0,
     "low-energy modes: gauss (the deck's particles and MLS integrated by stability.reference_order Gauss points "
     "per direction, no VCI: its lowest nonzero eigenvalue λ₁,ref is the scale), none (count zero modes only)"},
    {"stability.reference_order", MICA_KEY_INT, "4", 2, 20, NULL, 0, 0,
     "Gauss points per direction per cell of the reference (at least; the deck's own rule is the reference when it "
     "is Gauss of this order or more, without VCI)"},
    {"stability.low_energy_ratio", MICA_KEY_FLOAT, "0.1", 0, 1, NULL, 0, 0,
     "a nonzero mode v below λ₁,ref is a spurious low-energy mode when its energy under the deck's rule is less "
     "than low_energy_ratio times its energy under the reference: λ < ratio · vᵀK_ref v, |v| = 1 (docs/theory.md)"},
    {"stability.vtu_modes", MICA_KEY_INT, "4", 0, 1000, NULL, 0, 0,
     "mode shapes written as VTU: the spurious zero modes first, then the low-energy and the lowest nonzero modes"},
    {"stability.inf_sup_counts", MICA_KEY_INTS, "[5, 9, 17]", 2, 100000, NULL, 1, 0,
     "inf-sup: particles along the first axis of each refinement (the other axes keep the deck's spacing ratio)"},
    {"stability.chart", MICA_KEY_BOOL, "true", NOLIMIT, NULL, 0, 0, "draw spectrum.png and inf_sup.png with gnuplot"},
    {NULL, 0, NULL, 0, 0, NULL, 0, 0, NULL},
};
