// The .lcm definitions read at run time: the fingerprints lcm-gen computes,
// and a walk that finds every field of an encoded message where the
// generated classes put it.

#include <gtest/gtest.h>

#include <cstring>
#include <set>

#include "ofn/fuzz/lcm_schema.hpp"
#include "ofn/fuzz/message_support.hpp"

namespace ofn::fuzz {
namespace {

const Schema& schema() {
  static const Schema s = Schema::parse(builtin_lcm_sources());
  return s;
}

TEST(LcmSchema, ReadsEveryLcmFileOfTheProject) {
  // lcmtypes/ has one file per type; every one is built in and read.
  EXPECT_EQ(builtin_lcm_sources().size(), schema().types().size());
  ASSERT_NE(schema().find("nav_state_t"), nullptr);
  const auto& fields = schema().find("nav_state_t")->fields;
  ASSERT_EQ(fields.size(), 8u);
  EXPECT_EQ(fields[2].name, "position");
  ASSERT_EQ(fields[2].dims.size(), 1u);
  EXPECT_FALSE(fields[2].dims[0].variable);
  const auto& path = schema().find("global_path_t")->fields;
  EXPECT_EQ(path.back().name, "points");
  ASSERT_EQ(path.back().dims.size(), 2u);
  EXPECT_TRUE(path.back().dims[0].variable);
  EXPECT_EQ(path.back().dims[0].size, "num_points");
}

TEST(LcmSchema, FingerprintsAreTheGeneratedClassesOwn) {
  // Each channel type's fingerprint covers the types nested in it
  // (limits_t, waypoint_t, cuboid_t, obstacle_t) as the generated
  // _computeHash does.
  for (const auto& s : message_supports())
    EXPECT_EQ(schema().fingerprint(s.type), s.fingerprint) << s.type;
  EXPECT_THROW(schema().fingerprint("no_such_t"), std::out_of_range);
}

TEST(LcmSchema, WalksNavStateFieldByField) {
  const auto bytes = find_message_support("nav_state_t")->seed();
  const auto slots = schema().walk("nav_state_t", bytes.data(), bytes.size());
  // utime, frame, 3 + 3 + 3 + 4 + 3 + 3 doubles.
  ASSERT_EQ(slots.size(), 21u);
  EXPECT_EQ(slots[0].kind, SlotKind::kStamp);
  EXPECT_EQ(slots[0].offset, 8u);
  EXPECT_EQ(slots[1].kind, SlotKind::kStringLength);
  EXPECT_EQ(slots[1].value, 4);  // "NED" and its NUL
  EXPECT_EQ(slots[2].path, "position[0]");
  EXPECT_EQ(slots[2].offset, 8u + 8 + 4 + 4);
  EXPECT_EQ(slots[2].kind, SlotKind::kDouble);
  EXPECT_EQ(slots.back().path, "body_rates[2]");
  EXPECT_EQ(slots.back().offset + 8, bytes.size());
}

TEST(LcmSchema, WalksNestedStructsCountsAndTwoDimensionalArrays) {
  const auto mission = find_message_support("mission_t")->seed();
  const auto m = schema().walk("mission_t", mission.data(), mission.size());
  std::set<std::string> paths;
  for (const auto& s : m) paths.insert(s.path);
  EXPECT_TRUE(paths.count("limits.max_speed"));
  EXPECT_TRUE(paths.count("waypoints[1].capture_radius"));
  const auto count =
      std::find_if(m.begin(), m.end(), [](const Slot& s) { return s.path == "num_waypoints"; });
  ASSERT_NE(count, m.end());
  EXPECT_EQ(count->kind, SlotKind::kCount);
  EXPECT_EQ(count->value, 2);
  const auto traj = find_message_support("ref_traj_t")->seed();
  const auto t = schema().walk("ref_traj_t", traj.data(), traj.size());
  paths.clear();
  for (const auto& s : t) paths.insert(s.path);
  EXPECT_TRUE(paths.count("t0_utime"));
  EXPECT_TRUE(paths.count("acceleration[2][2]"));
  EXPECT_EQ(
      std::count_if(t.begin(), t.end(), [](const Slot& s) { return s.kind == SlotKind::kStamp; }),
      2);
}

TEST(LcmSchema, EveryNumberTheWalkFindsIsOneTheDecoderReads) {
  // A marker written at each float and double the walk finds survives the
  // generated decoder and encoder unchanged, and the walk of every seed
  // ends exactly at the end of its bytes: each slot is a field where the
  // generated class has it.
  for (const auto& s : message_supports()) {
    const auto seed = s.seed();
    const auto slots = schema().walk(s.type, seed.data(), seed.size());
    ASSERT_EQ(s.check(seed.data(), seed.size()), "") << s.type << "'s seed is not valid";
    for (const auto& slot : slots) {
      if (slot.kind != SlotKind::kDouble && slot.kind != SlotKind::kFloat) continue;
      auto marked = seed;
      for (size_t i = 0; i < slot.size; ++i)
        marked[slot.offset + i] = static_cast<uint8_t>(0x41 + i);
      const auto again = s.reencode(marked.data(), marked.size());
      ASSERT_TRUE(again.has_value()) << s.type << " " << slot.path;
      EXPECT_EQ(*again, marked) << s.type << " " << slot.path;
      EXPECT_NE(marked, seed);
    }
  }
}

TEST(LcmSchema, WalksEmptyArraysOfFixedSizeElements) {
  // No passage: centre[0][3], radius[0], half_height[0].
  const auto full = find_message_support("narrow_passages_t")->seed();
  const auto s = schema().walk("narrow_passages_t", full.data(), full.size());
  auto count =
      std::find_if(s.begin(), s.end(), [](const Slot& x) { return x.kind == SlotKind::kCount; });
  ASSERT_NE(count, s.end());
  // The same message cut after its count, and the count set to 0.
  std::vector<uint8_t> empty(full.begin(),
                             full.begin() + static_cast<std::ptrdiff_t>(count->offset + 4));
  for (int i = 0; i < 4; ++i) empty[count->offset + i] = 0;
  const auto e = schema().walk("narrow_passages_t", empty.data(), empty.size());
  EXPECT_EQ(e.back().kind, SlotKind::kCount);
  EXPECT_EQ(e.back().value, 0);
  EXPECT_EQ(find_message_support("narrow_passages_t")->check(empty.data(), empty.size()), "");
}

TEST(LcmSchema, WalkRefusesWhatIsNotOneWholeMessage) {
  auto bytes = find_message_support("mission_t")->seed();
  EXPECT_THROW(schema().walk("mission_t", bytes.data(), bytes.size() - 1), std::invalid_argument);
  auto longer = bytes;
  longer.push_back(0);
  EXPECT_THROW(schema().walk("mission_t", longer.data(), longer.size()), std::invalid_argument);
  EXPECT_THROW(schema().walk("nav_state_t", bytes.data(), bytes.size()), std::invalid_argument);
  EXPECT_THROW(schema().walk("mission_t", bytes.data(), 4), std::invalid_argument);
}

void expect_schema_error(const std::string& text, const std::string& wanted) {
  try {
    Schema::parse({{"bad.lcm", text}});
    ADD_FAILURE() << "no error for: " << text;
  } catch (const SchemaError& e) {
    EXPECT_NE(std::string(e.what()).find(wanted), std::string::npos) << e.what();
  }
}

TEST(LcmSchema, ABadDefinitionIsAnErrorNamingItsFileAndLine) {
  expect_schema_error("package p;\nstruct a_t\n{\n  double x\n}\n", "bad.lcm:5: expected ';'");
  expect_schema_error("struct a_t { b_t x; }", "unknown type 'b_t'");
  expect_schema_error(
      "struct a_t {\n double v[n];\n int32_t n; }",
      "bad.lcm:2: array 'v' is sized by 'n', which is not an earlier integer field");
  expect_schema_error("struct a_t { double n; double v[n]; }", "not an earlier integer field");
  expect_schema_error("struct a_t { double x; double x; }", "field 'x' defined twice");
  expect_schema_error("struct a_t { double x; /* open", "unterminated comment");
  expect_schema_error("struct a_t { double x;", "end of file");
  // Constants take no bytes, and several fields may share a declaration.
  const Schema s = Schema::parse(
      {{"ok.lcm", "package p; struct a_t { const int8_t A = 1, B = 2; double x, y[2]; }"}});
  ASSERT_NE(s.find("a_t"), nullptr);
  EXPECT_EQ(s.find("a_t")->fields.size(), 2u);
  EXPECT_EQ(s.find("a_t")->fields[1].dims.size(), 1u);
}

}  // namespace
}  // namespace ofn::fuzz
