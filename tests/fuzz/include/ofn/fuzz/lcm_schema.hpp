#pragma once
// The message types as lcmtypes/*.lcm define them, read at run time: their
// fields, their fingerprints (computed as lcm-gen computes getHash()) and a
// walk over an encoded message that finds every field's bytes. The bus
// fuzz places its hostile values with it (a NaN in every double, a huge
// count in every array's size field), so that a field added to a .lcm file
// is fuzzed without a line of the fuzz changing.
//
// Only what the project's .lcm files use and LCM's grammar allows is read:
// `package`, structs with primitive, struct-typed and array fields (fixed
// or sized by an earlier integer field, any number of dimensions), and
// constants (which take no bytes). Enums are not read.

#include <cstddef>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace ofn::fuzz {

/// A .lcm source: its file name (for errors) and its text.
struct LcmSource {
  std::string file;
  std::string text;
};

/// The .lcm files of lcmtypes/, built into the program (lcm_sources.cpp,
/// generated from the folder by tests/fuzz/CMakeLists.txt).
const std::vector<LcmSource>& builtin_lcm_sources();

struct LcmDimension {
  bool variable = false;  // sized by the field named `size`, else a fixed count
  std::string size;       // "3", or "num_points"
};

struct LcmField {
  std::string name;
  std::string type;  // "double", "string", ... or a struct's short name ("limits_t")
  std::vector<LcmDimension> dims;
};

struct LcmStruct {
  std::string name;  // short name, "nav_state_t"
  std::string file;
  std::vector<LcmField> fields;
};

/// A malformed .lcm source: the file and line, and what was expected.
class SchemaError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// What one field's bytes are, for the fuzz.
enum class SlotKind {
  kInt8,
  kInt16,
  kInt32,
  kInt64,
  kByte,
  kBoolean,
  kFloat,
  kDouble,
  kStringLength,  // the int32 before a string's bytes (length + 1 for its NUL)
  kCount,         // an integer field another field is sized by
  kStamp,         // an int64 named utime or *_utime (microseconds)
};

const char* slot_kind_name(SlotKind kind);

/// One field (one element of an array) of an encoded message.
struct Slot {
  size_t offset = 0;  // from the start of the encoding (the fingerprint is bytes 0-7)
  size_t size = 0;    // bytes: 1, 2, 4 or 8
  SlotKind kind = SlotKind::kInt32;
  std::string path;   // "waypoints[1].position[2]"
  int64_t value = 0;  // its value, for the integer kinds
};

class Schema {
 public:
  /// Reads the sources; throws SchemaError naming the file and line of
  /// anything it cannot read, a type defined twice or a field of an
  /// unknown type, or sized by a field that is not an earlier integer.
  static Schema parse(const std::vector<LcmSource>& sources);

  /// The struct named `type` (short name), or nullptr.
  const LcmStruct* find(const std::string& type) const;
  /// Every struct's short name, sorted.
  std::vector<std::string> types() const;

  /// The 64-bit fingerprint an encoding of `type` starts with, equal to
  /// the generated class's getHash(). Throws std::out_of_range for an
  /// unknown type.
  int64_t fingerprint(const std::string& type) const;

  /// Every field of `data`, an encoding of `type` with its fingerprint, in
  /// byte order (a string is its kStringLength slot; its characters are
  /// no slot). Throws std::invalid_argument when the bytes are not one
  /// whole message of the type: a wrong fingerprint, a count or length
  /// past the end, bytes left over.
  std::vector<Slot> walk(const std::string& type, const uint8_t* data, size_t size) const;

 private:
  uint64_t compute_hash(const std::string& type, std::vector<std::string>& parents) const;
  std::map<std::string, LcmStruct> structs_;
};

}  // namespace ofn::fuzz
