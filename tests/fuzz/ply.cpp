// libFuzzer target: the ply shape plugin (ascii and binary PLY files).
#include "mesh_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    return facet::fuzz::load_mesh("ply", ".ply", data, size);
}
