// pmr_studio_gen OUT.bin: prefilters the built-in studio environment (shading/studio_environment.h) and
// writes its tables, run by the build (CMakeLists.txt) so that no pbr process waits for the prefilter
// (about 0.35 s on 2 cores). The file is the EnvTablesHeader's bytes, then the floats; the build
// embeds it (generated/studio_tables.S) and Environment::studio() reads it back.
#include <cstdio>

#include "shading/environment_prefilter.h"
#include "shading/studio_environment.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: pmr_studio_gen OUT.bin\n");
    return 2;
  }
  const pmr::EnvironmentTables t = pmr::prefilter_environment(pmr::studio_environment_image());
  std::FILE* f = std::fopen(argv[1], "wb");
  if (!f) {
    std::perror(argv[1]);
    return 1;
  }
  const bool written = std::fwrite(&t.header, sizeof t.header, 1, f) == 1 &&
                       std::fwrite(t.data.data(), sizeof(float), t.data.size(), f) == t.data.size();
  if (std::fclose(f) != 0 || !written) {
    std::perror(argv[1]);
    return 1;
  }
  return 0;
}
