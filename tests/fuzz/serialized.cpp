// libFuzzer target: the serialized shape plugin (Mitsuba's zlib-compressed mesh format).
#include "mesh_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    return facet::fuzz::load_mesh("serialized", ".serialized", data, size);
}
