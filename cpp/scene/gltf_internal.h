// Internal to the glTF reader and writer (gltf_checks.cpp, gltf_read.cpp, gltf_write.cpp):
// what the checks made before any parser runs hand on to the reader.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace ssr::gltf_detail {

namespace fs = std::filesystem;

constexpr int kModeTriangles = 4, kModeStrip = 5, kModeFan = 6;
constexpr uint64_t kMaxFileBytes = uint64_t(1) << 30;  // per file read: the model, each buffer, each image
constexpr int kMaxNodeDepth = 1000;                    // node hierarchy levels

inline bool checked_add(uint64_t a, uint64_t b, uint64_t* out) { return !__builtin_add_overflow(a, b, out); }
inline bool checked_mul(uint64_t a, uint64_t b, uint64_t* out) { return !__builtin_mul_overflow(a, b, out); }

// A message Python can always decode: bytes that are not UTF-8, and control characters,
// become \xNN (a file name or a JSON parser's excerpt can hold anything).
std::string printable(std::string_view s);

// Reads a regular file of at most kMaxFileBytes (devices, FIFOs and folders refused unread).
std::vector<uint8_t> read_regular_file(const std::string& path, const std::string& what);

// Where a model may read files from.
struct PathPolicy {
    std::string file;      // the model, for messages
    fs::path dir;          // its folder (absolute)
    fs::path dir_real;     // the same with symlinks resolved
    bool allow_external = false;
};

// A file the model refers to, checked for being readable under `pol`; its real path.
fs::path resolve_reference(const PathPolicy& pol, const std::string& ref, const std::string& what);

// tinygltf opens external files only through these: a path the pre-check approved (keyed by
// the path tinygltf builds) is read from its checked real location; anything else is refused.
struct FsContext {
    std::map<std::string, std::string> approved;
};
bool fs_exists(const std::string& path, void* user);
std::string fs_expand(const std::string& path, void*);
bool fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user);
bool fs_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*);

// The JSON text's problem (not UTF-8, nested too deep) or an empty string.
std::string check_json_text(std::string_view text);

inline uint32_t read_u32(const uint8_t* p) {  // GLB is little-endian
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

// The extensions ssrlab renders; any other in extensionsRequired is refused, in extensionsUsed warned.
const std::set<std::string>& implemented_extensions();

// Checks what tinygltf would otherwise trust and approves the external files it may read.
void precheck_json(const nlohmann::json& j, const PathPolicy& pol, const std::string& base_dir, bool glb,
                   uint64_t glb_bin_size, FsContext* ctx);

}  // namespace ssr::gltf_detail
