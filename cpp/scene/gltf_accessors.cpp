// Buffers, bufferViews and accessors (glTF 2.0, binary data storage): GltfReader's checked reads.

#include "scene/gltf_reader.h"

namespace ssr::gltf_detail {

std::vector<uint32_t> GltfReader::read_indices(int index, const std::string& what) const {
    const auto& acc = accessor(index, what);
    if (acc.sparse.isSparse) fail(what + ": sparse accessor " + std::to_string(index) + " is not supported");
    if (acc.type != TINYGLTF_TYPE_SCALAR) fail(what + ": index accessor " + std::to_string(index) + " is not SCALAR");
    if (acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        fail(what + ": index accessor " + std::to_string(index) + " has component type " +
             std::to_string(acc.componentType) + "; indices must be unsigned byte, short or int");
    const auto [data, stride, elem] = view(acc, index, what);
    std::vector<uint32_t> out(acc.count);
    for (size_t i = 0; i < acc.count; ++i) {
        const uint8_t* p = data + i * stride;
        switch (acc.componentType) {
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: out[i] = *p; break;
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t v; std::memcpy(&v, p, 2); out[i] = v; break; }
            default: { uint32_t v; std::memcpy(&v, p, 4); out[i] = v; break; }
        }
    }
    return out;
}

std::vector<glm::vec4> GltfReader::read_colors(int index, const std::string& what) const {
    const auto& acc = accessor(index, what);
    const bool normalized_int = acc.normalized && (acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                                   acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
    if (acc.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT && !normalized_int)
        fail(what + ": accessor " + std::to_string(index) +
             " must be float or normalized unsigned byte or short (glTF COLOR_n)");
    if (acc.type == TINYGLTF_TYPE_VEC4) return read_floats<4>(index, what);
    if (acc.type != TINYGLTF_TYPE_VEC3) fail(what + ": accessor " + std::to_string(index) + " must be VEC3 or VEC4");
    std::vector<glm::vec4> out;
    for (const auto& c : read_floats<3>(index, what)) out.emplace_back(c, 1.0f);
    return out;
}

const tinygltf::Accessor& GltfReader::accessor(int index, const std::string& what) const {
    if (index < 0 || index >= int(model_.accessors.size()))
        fail(what + ": accessor index " + std::to_string(index) + " is out of range (the file has " +
             std::to_string(model_.accessors.size()) + " accessors)");
    return model_.accessors[size_t(index)];
}

GltfReader::View GltfReader::view(const tinygltf::Accessor& acc, int index, const std::string& what) const {
    const std::string a = what + ": accessor " + std::to_string(index);
    if (acc.bufferView < 0)
        fail(a + " has no bufferView (accessors without data are not supported)");
    if (acc.bufferView >= int(model_.bufferViews.size()))
        fail(a + " refers to bufferView " + std::to_string(acc.bufferView) + ", out of range (the file has " +
             std::to_string(model_.bufferViews.size()) + ")");
    const auto& bv = model_.bufferViews[size_t(acc.bufferView)];
    const std::string v = "bufferView " + std::to_string(acc.bufferView);
    if (bv.buffer < 0 || bv.buffer >= int(model_.buffers.size()))
        fail(a + ": " + v + " refers to buffer " + std::to_string(bv.buffer) + ", out of range");
    const auto& buf = model_.buffers[size_t(bv.buffer)];
    const int comp_size = tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType));
    const int comps = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
    if (comp_size <= 0 || comps <= 0) fail(a + " has an invalid component type or element type");
    if (acc.count == 0) fail(a + " has count 0");
    const uint64_t elem = uint64_t(comp_size) * uint64_t(comps);
    const uint64_t stride = bv.byteStride ? uint64_t(bv.byteStride) : elem;
    if (stride < elem)
        fail(a + ": " + v + "'s byteStride " + std::to_string(stride) + " is smaller than an element (" +
             std::to_string(elem) + " bytes)");
    uint64_t view_end = 0, span = 0, acc_end = 0, begin = 0;
    if (!checked_add(bv.byteOffset, bv.byteLength, &view_end) || view_end > buf.data.size())
        fail(v + ": byteOffset " + std::to_string(bv.byteOffset) + " + byteLength " + std::to_string(bv.byteLength) +
             " lies outside buffer " + std::to_string(bv.buffer) + " (" + std::to_string(buf.data.size()) + " bytes)");
    if (!checked_mul(stride, uint64_t(acc.count) - 1, &span) || !checked_add(span, elem, &span) ||
        !checked_add(acc.byteOffset, span, &acc_end) || acc_end > bv.byteLength)
        fail(a + ": byteOffset " + std::to_string(acc.byteOffset) + " and count " + std::to_string(acc.count) +
             " read past the end of " + v + " (" + std::to_string(bv.byteLength) + " bytes)");
    checked_add(bv.byteOffset, acc.byteOffset, &begin);  // < view_end, cannot overflow
    return View{buf.data.data() + begin, size_t(stride), size_t(elem)};
}


}  // namespace ssr::gltf_detail
