// libFuzzer target: the obj shape plugin (Wavefront OBJ files).
#include "mesh_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    return facet::fuzz::load_mesh("obj", ".obj", data, size);
}
