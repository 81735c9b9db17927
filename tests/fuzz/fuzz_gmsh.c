/* libFuzzer harness of the Gmsh reader (`make fuzz`; docs/verification.md "Fuzzing"): the input is written
 * to a .msh file and read as `geometry.shape = "gmsh"` reads it, through mica_discretization_create: the
 * reader (gmsh.c: $MeshFormat, $PhysicalNames, $Entities, $Nodes, $Elements in 4.1 ASCII and binary;
 * gmsh_v22.c: 2.2 ASCII), then the mesh's particles, quadrature, boundary sets and cells (mesh.c,
 * cell_mesh.c). Every outcome but a crash, a hang or a leak is fine: a mesh either loads or is refused. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "mica/error.h"
#include "mica/geom.h"

static char mesh_path[512];

int LLVMFuzzerInitialize(int *argc, char ***argv) {
  (void)argc, (void)argv;
  char dir[] = "/tmp/mica-fuzz-gmsh-XXXXXX";
  if (!mkdtemp(dir)) abort();
  snprintf(mesh_path, sizeof mesh_path, "%s/mesh.msh", dir);
  return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  FILE *f = fopen(mesh_path, "wb");
  if (!f) abort();
  if (size && fwrite(data, 1, size, f) != size) abort();
  fclose(f);
  const MicaShapeSpec shape = {.kind = MICA_SHAPE_GMSH, .mesh_path = mesh_path};
  const MicaLayoutSpec layout = {0};
  const MicaCellSpec cells = {.order = 2};
  MicaDiscretization *disc = NULL;
  mica_discretization_create(&shape, &layout, &cells, &disc);
  mica_discretization_destroy(&disc);
  mica_error_clear();
  return 0;
}
