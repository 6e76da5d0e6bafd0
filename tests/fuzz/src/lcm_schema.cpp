#include "ofn/fuzz/lcm_schema.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <set>

namespace ofn::fuzz {
namespace {

const std::map<std::string, size_t>& primitive_sizes() {
  // string: its length field; its bytes follow.
  static const std::map<std::string, size_t> sizes = {
      {"int8_t", 1},  {"int16_t", 2}, {"int32_t", 4}, {"int64_t", 8}, {"byte", 1},
      {"boolean", 1}, {"float", 4},   {"double", 8},  {"string", 4}};
  return sizes;
}

bool is_primitive(const std::string& type) {
  return primitive_sizes().count(type) > 0;
}

bool is_integer(const std::string& type) {
  return type == "int8_t" || type == "int16_t" || type == "int32_t" || type == "int64_t";
}

struct Token {
  std::string text;
  int line = 0;
};

/// Identifiers, numbers and the punctuation of the grammar; comments
/// dropped.
std::vector<Token> tokenize(const LcmSource& source) {
  std::vector<Token> tokens;
  const std::string& s = source.text;
  int line = 1;
  size_t i = 0;
  while (i < s.size()) {
    const char c = s[i];
    if (c == '\n') {
      ++line;
      ++i;
    } else if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
    } else if (s.compare(i, 2, "//") == 0) {
      while (i < s.size() && s[i] != '\n') ++i;
    } else if (s.compare(i, 2, "/*") == 0) {
      const size_t end = s.find("*/", i + 2);
      if (end == std::string::npos)
        throw SchemaError(source.file + ":" + std::to_string(line) + ": unterminated comment");
      line += static_cast<int>(std::count(s.begin() + static_cast<std::ptrdiff_t>(i),
                                          s.begin() + static_cast<std::ptrdiff_t>(end), '\n'));
      i = end + 2;
    } else if (std::strchr("{}[];,=", c) != nullptr) {
      tokens.push_back({std::string(1, c), line});
      ++i;
    } else if (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ||
               c == '+') {
      size_t j = i;
      while (j < s.size() && (std::isalnum(static_cast<unsigned char>(s[j])) || s[j] == '_' ||
                              s[j] == '.' || s[j] == '-' || s[j] == '+'))
        ++j;
      tokens.push_back({s.substr(i, j - i), line});
      i = j;
    } else {
      throw SchemaError(source.file + ":" + std::to_string(line) + ": unexpected character '" +
                        std::string(1, c) + "'");
    }
  }
  return tokens;
}

class Parser {
 public:
  Parser(const LcmSource& source) : source_(source), tokens_(tokenize(source)) {}

  std::vector<LcmStruct> parse() {
    std::vector<LcmStruct> structs;
    while (!done()) {
      const Token t = next("'package' or 'struct'");
      if (t.text == "package") {
        next("a package name");
        expect(";");
      } else if (t.text == "struct") {
        structs.push_back(parse_struct());
      } else {
        fail(t, "expected 'package' or 'struct', found '" + t.text + "'");
      }
    }
    return structs;
  }

 private:
  LcmStruct parse_struct() {
    LcmStruct st;
    st.name = identifier("a struct name");
    st.file = source_.file;
    expect("{");
    while (peek("a field or '}'").text != "}") {
      if (peek("a field").text == "const") {
        next("const");
        next("a constant's type");
        do {
          identifier("a constant's name");
          expect("=");
          next("a constant's value");
        } while (accept(","));
        expect(";");
        continue;
      }
      std::string type = identifier("a field's type");
      if (const size_t dot = type.rfind('.'); dot != std::string::npos) type = type.substr(dot + 1);
      do {
        LcmField field;
        field.type = type;
        const Token name = peek("a field's name");
        field.name = identifier("a field's name");
        while (accept("[")) {
          const Token size = next("an array size");
          LcmDimension dim;
          dim.size = size.text;
          dim.variable = !std::isdigit(static_cast<unsigned char>(size.text[0]));
          if (dim.variable) {
            const auto earlier =
                std::find_if(st.fields.begin(), st.fields.end(),
                             [&](const LcmField& f) { return f.name == size.text; });
            if (earlier == st.fields.end() || !is_integer(earlier->type) || !earlier->dims.empty())
              fail(size, "array '" + field.name + "' is sized by '" + size.text +
                             "', which is not an earlier integer field");
          }
          field.dims.push_back(dim);
          expect("]");
        }
        for (const auto& f : st.fields)
          if (f.name == field.name) fail(name, "field '" + field.name + "' defined twice");
        st.fields.push_back(field);
      } while (accept(","));
      expect(";");
    }
    expect("}");
    return st;
  }

  bool done() const { return pos_ >= tokens_.size(); }
  [[noreturn]] void fail(const Token& at, const std::string& what) const {
    throw SchemaError(source_.file + ":" + std::to_string(at.line) + ": " + what);
  }
  const Token& peek(const std::string& wanted) const {
    if (done()) {
      const int line = tokens_.empty() ? 1 : tokens_.back().line;
      throw SchemaError(source_.file + ":" + std::to_string(line) + ": end of file, expected " +
                        wanted);
    }
    return tokens_[pos_];
  }
  Token next(const std::string& wanted) {
    const Token t = peek(wanted);
    ++pos_;
    return t;
  }
  std::string identifier(const std::string& wanted) {
    const Token t = next(wanted);
    if (!(std::isalpha(static_cast<unsigned char>(t.text[0])) || t.text[0] == '_'))
      fail(t, "expected " + wanted + ", found '" + t.text + "'");
    return t.text;
  }
  void expect(const std::string& text) {
    const Token t = next("'" + text + "'");
    if (t.text != text) fail(t, "expected '" + text + "', found '" + t.text + "'");
  }
  bool accept(const std::string& text) {
    if (done() || tokens_[pos_].text != text) return false;
    ++pos_;
    return true;
  }

  const LcmSource& source_;
  std::vector<Token> tokens_;
  size_t pos_ = 0;
};

// lcm-gen's hash steps (lcmgen.c): a shift-and-add over the field names,
// primitive types and dimensions, on a signed 64-bit value (the right
// shift is arithmetic, as its C is on every compiler LCM supports).
int64_t hash_update(int64_t v, char c) {
  const uint64_t left = static_cast<uint64_t>(v) << 8;
  const uint64_t right = static_cast<uint64_t>(v >> 55);
  return static_cast<int64_t>((left ^ right) + static_cast<uint64_t>(static_cast<int64_t>(c)));
}

int64_t hash_string_update(int64_t v, const std::string& s) {
  v = hash_update(v, static_cast<char>(s.size()));
  for (char c : s) v = hash_update(v, c);
  return v;
}

int64_t struct_hash(const LcmStruct& st) {
  int64_t v = 0x12345678;
  for (const auto& f : st.fields) {
    v = hash_string_update(v, f.name);
    if (is_primitive(f.type)) v = hash_string_update(v, f.type);
    v = hash_update(v, static_cast<char>(f.dims.size()));
    for (const auto& d : f.dims) {
      v = hash_update(v, static_cast<char>(d.variable ? 1 : 0));  // LCM_CONST 0, LCM_VAR 1
      v = hash_string_update(v, d.size);
    }
  }
  return v;
}

int64_t read_be(const uint8_t* p, size_t size) {
  uint64_t v = 0;
  for (size_t i = 0; i < size; ++i) v = (v << 8) | p[i];
  // Sign-extend from `size` bytes.
  const unsigned shift = static_cast<unsigned>(64 - 8 * size);
  return static_cast<int64_t>(v << shift) >> shift;
}

bool is_stamp_name(const std::string& name) {
  return name == "utime" || (name.size() > 6 && name.compare(name.size() - 6, 6, "_utime") == 0);
}

class Walker {
 public:
  Walker(const Schema& schema, const uint8_t* data, size_t size)
      : schema_(schema), data_(data), size_(size) {}

  void walk_struct(const LcmStruct& st, const std::string& prefix) {
    std::set<std::string> counts;
    for (const auto& f : st.fields)
      for (const auto& d : f.dims)
        if (d.variable) counts.insert(d.size);
    std::map<std::string, int64_t> values;
    for (const auto& f : st.fields) {
      std::vector<int64_t> extents;
      for (const auto& d : f.dims) {
        const int64_t n = d.variable ? values.at(d.size) : std::stoll(d.size);
        // A count read from the message is bounded by the bytes left before
        // anything is walked (every element takes at least one); a fixed
        // one is the definition's, and may follow an empty dimension.
        if (d.variable && n < 0)
          throw std::invalid_argument(prefix + f.name + ": negative count " + std::to_string(n));
        if (d.variable && n > static_cast<int64_t>(size_ - pos_))
          throw std::invalid_argument(prefix + f.name + ": count " + std::to_string(n) +
                                      " past the end");
        extents.push_back(n);
      }
      const SlotKind int_kind = counts.count(f.name)                           ? SlotKind::kCount
                                : is_stamp_name(f.name) && f.type == "int64_t" ? SlotKind::kStamp
                                                                               : SlotKind::kInt64;
      walk_array(f, extents, 0, prefix + f.name, int_kind, &values);
    }
  }

  std::vector<Slot> slots;
  size_t pos_ = 0;

 private:
  void walk_array(const LcmField& f, const std::vector<int64_t>& extents, size_t dim,
                  const std::string& path, SlotKind int_kind,
                  std::map<std::string, int64_t>* values) {
    if (dim == extents.size()) {
      walk_one(f, path, int_kind, values);
      return;
    }
    for (int64_t i = 0; i < extents[dim]; ++i)
      walk_array(f, extents, dim + 1, path + "[" + std::to_string(i) + "]", int_kind, values);
  }

  void walk_one(const LcmField& f, const std::string& path, SlotKind int_kind,
                std::map<std::string, int64_t>* values) {
    if (!is_primitive(f.type)) {
      const LcmStruct* sub = schema_.find(f.type);
      walk_struct(*sub, path + ".");
      return;
    }
    const size_t size = primitive_sizes().at(f.type);
    need(size, path);
    Slot slot;
    slot.offset = pos_;
    slot.size = size;
    slot.path = path;
    if (f.type == "string") {
      slot.kind = SlotKind::kStringLength;
      slot.value = read_be(data_ + pos_, 4);
      pos_ += 4;
      if (slot.value < 1 || slot.value > static_cast<int64_t>(size_ - pos_))
        throw std::invalid_argument(path + ": string length " + std::to_string(slot.value) +
                                    " outside the message");
      pos_ += static_cast<size_t>(slot.value);
      slots.push_back(slot);
      return;
    }
    if (f.type == "float") {
      slot.kind = SlotKind::kFloat;
    } else if (f.type == "double") {
      slot.kind = SlotKind::kDouble;
    } else if (f.type == "boolean") {
      slot.kind = SlotKind::kBoolean;
      slot.value = data_[pos_];
    } else if (f.type == "byte") {
      slot.kind = SlotKind::kByte;
      slot.value = data_[pos_];
    } else {
      slot.value = read_be(data_ + pos_, size);
      if (int_kind == SlotKind::kCount || int_kind == SlotKind::kStamp)
        slot.kind = int_kind;
      else
        slot.kind = size == 1   ? SlotKind::kInt8
                    : size == 2 ? SlotKind::kInt16
                    : size == 4 ? SlotKind::kInt32
                                : SlotKind::kInt64;
      // A count is a scalar: the dimension it sizes reads it by name.
      (*values)[f.name] = slot.value;
    }
    pos_ += size;
    slots.push_back(slot);
  }

  void need(size_t n, const std::string& path) const {
    if (n > size_ - pos_) throw std::invalid_argument(path + ": past the end of the message");
  }

  const Schema& schema_;
  const uint8_t* data_;
  size_t size_;
};

}  // namespace

const char* slot_kind_name(SlotKind kind) {
  switch (kind) {
    case SlotKind::kInt8:
      return "int8";
    case SlotKind::kInt16:
      return "int16";
    case SlotKind::kInt32:
      return "int32";
    case SlotKind::kInt64:
      return "int64";
    case SlotKind::kByte:
      return "byte";
    case SlotKind::kBoolean:
      return "boolean";
    case SlotKind::kFloat:
      return "float";
    case SlotKind::kDouble:
      return "double";
    case SlotKind::kStringLength:
      return "string length";
    case SlotKind::kCount:
      return "count";
    case SlotKind::kStamp:
      return "stamp";
  }
  return "?";
}

Schema Schema::parse(const std::vector<LcmSource>& sources) {
  Schema schema;
  for (const auto& source : sources) {
    for (auto& st : Parser(source).parse()) {
      if (schema.structs_.count(st.name))
        throw SchemaError(source.file + ": struct " + st.name + " is also defined in " +
                          schema.structs_.at(st.name).file);
      schema.structs_.emplace(st.name, std::move(st));
    }
  }
  for (const auto& [name, st] : schema.structs_)
    for (const auto& f : st.fields)
      if (!is_primitive(f.type) && !schema.structs_.count(f.type))
        throw SchemaError(st.file + ": field '" + f.name + "' of " + name + " has unknown type '" +
                          f.type + "'");
  return schema;
}

const LcmStruct* Schema::find(const std::string& type) const {
  const auto it = structs_.find(type);
  return it == structs_.end() ? nullptr : &it->second;
}

std::vector<std::string> Schema::types() const {
  std::vector<std::string> names;
  for (const auto& [name, st] : structs_) names.push_back(name);
  return names;
}

uint64_t Schema::compute_hash(const std::string& type, std::vector<std::string>& parents) const {
  // As the generated _computeHash: a type already on the way down adds
  // nothing; each struct-typed field adds its type's hash; then a rotation.
  if (std::find(parents.begin(), parents.end(), type) != parents.end()) return 0;
  const LcmStruct& st = structs_.at(type);
  parents.push_back(type);
  uint64_t hash = static_cast<uint64_t>(struct_hash(st));
  for (const auto& f : st.fields)
    if (!is_primitive(f.type)) hash += compute_hash(f.type, parents);
  parents.pop_back();
  return (hash << 1) + ((hash >> 63) & 1);
}

int64_t Schema::fingerprint(const std::string& type) const {
  if (!structs_.count(type)) throw std::out_of_range("no LCM type '" + type + "'");
  std::vector<std::string> parents;
  return static_cast<int64_t>(compute_hash(type, parents));
}

std::vector<Slot> Schema::walk(const std::string& type, const uint8_t* data, size_t size) const {
  const LcmStruct* st = find(type);
  if (st == nullptr) throw std::out_of_range("no LCM type '" + type + "'");
  if (size < 8) throw std::invalid_argument(type + ": shorter than a fingerprint");
  if (read_be(data, 8) != fingerprint(type))
    throw std::invalid_argument(type + ": not its fingerprint");
  Walker walker(*this, data, size);
  walker.pos_ = 8;
  walker.walk_struct(*st, "");
  if (walker.pos_ != size)
    throw std::invalid_argument(type + ": " + std::to_string(size - walker.pos_) +
                                " bytes after the message");
  return walker.slots;
}

}  // namespace ofn::fuzz
