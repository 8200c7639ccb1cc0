// The case schema's table (src/io/case_schema_table.cpp): structural facts of `sections()`.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "io/case_schema.hpp"

using namespace fdem::schema;

namespace {

const Section* section_at(const std::string& path) {
  for (const Section& s : sections())
    if (s.path == path) return &s;
  return nullptr;
}

bool has_key(const Section& s, const std::string& name) {
  return std::any_of(s.keys.begin(), s.keys.end(), [&](const Key& k) { return k.name == name; });
}

const Key* key_of(const Section& s, const std::string& name) {
  for (const Key& k : s.keys)
    if (k.name == name) return &k;
  return nullptr;
}

bool numeric(Type t) {
  return t == Type::kNumber || t == Type::kInteger || t == Type::kVec3 || t == Type::kNumbers || t == Type::kAny;
}

}  // namespace

TEST(CaseSchema, TopLevelFirst) {
  ASSERT_FALSE(sections().empty());
  EXPECT_EQ(sections().front().path, "");
  EXPECT_FALSE(sections().front().keys.empty());
}

TEST(CaseSchema, SectionPathsUniqueAndWithoutIndices) {
  std::set<std::string> seen;
  for (const Section& s : sections()) {
    EXPECT_TRUE(seen.insert(s.path).second) << "duplicate section '" << s.path << "'";
    EXPECT_EQ(s.path.find('['), std::string::npos) << s.path;
    EXPECT_FALSE(s.keys.empty()) << "section '" << s.path << "' has no keys";
    if (!s.path.empty()) {
      EXPECT_NE(s.path.front(), '.') << s.path;
      EXPECT_NE(s.path.back(), '.') << s.path;
    }
  }
}

TEST(CaseSchema, KeyNamesUniqueWithinASection) {
  for (const Section& s : sections()) {
    std::set<std::string> seen;
    for (const Key& k : s.keys) {
      EXPECT_FALSE(k.name.empty()) << "a key without a name in '" << s.path << "'";
      EXPECT_EQ(k.name.find('.'), std::string::npos) << s.path << ": " << k.name;
      EXPECT_TRUE(seen.insert(k.name).second) << "duplicate key '" << k.name << "' in '" << s.path << "'";
    }
  }
}

TEST(CaseSchema, ChildSectionsExist) {
  std::set<std::string> referenced;
  for (const Section& s : sections())
    for (const Key& k : s.keys) {
      const std::string where = s.path + "." + k.name;
      if (k.type == Type::kMap || k.type == Type::kList)
        EXPECT_FALSE(k.section.empty()) << where << ": a mapping or list without its section";
      else if (k.type != Type::kAny)
        EXPECT_TRUE(k.section.empty()) << where << ": only mappings, lists and kAny have a section";
      if (k.section.empty()) continue;
      EXPECT_NE(section_at(k.section), nullptr) << where << ": no section '" << k.section << "'";
      referenced.insert(k.section);
    }
  // and every section but the top level is some key's child (none is unreachable)
  for (const Section& s : sections())
    if (!s.path.empty()) EXPECT_TRUE(referenced.count(s.path)) << "section '" << s.path << "' is no key's section";
}

TEST(CaseSchema, VariantsNameKeysOfTheirSection) {
  for (const Section& s : sections()) {
    if (!s.variant_key.empty()) {
      const Key* vk = key_of(s, s.variant_key);
      ASSERT_NE(vk, nullptr) << s.path << ": variant key '" << s.variant_key << "' is not a key";
      ASSERT_EQ(vk->type, Type::kEnum) << s.path << "." << s.variant_key;
      // one variant per value of the variant key
      std::vector<std::string> names;
      for (const auto& v : s.variants) names.push_back(v.first);
      EXPECT_EQ(names, vk->values) << s.path;
      EXPECT_FALSE(s.variants.empty()) << s.path;
    }
    std::set<std::string> variant_names, used;
    for (const auto& [name, keys] : s.variants) {
      EXPECT_TRUE(variant_names.insert(name).second) << s.path << ": duplicate variant '" << name << "'";
      EXPECT_FALSE(keys.empty()) << s.path << ": variant '" << name << "' has no keys";
      std::set<std::string> seen;
      for (const std::string& k : keys) {
        EXPECT_TRUE(has_key(s, k)) << s.path << ": variant '" << name << "' names '" << k << "', not a key of the section";
        EXPECT_TRUE(seen.insert(k).second) << s.path << ": variant '" << name << "' names '" << k << "' twice";
        used.insert(k);
      }
      if (!s.variant_key.empty())
        EXPECT_TRUE(seen.count(s.variant_key)) << s.path << ": variant '" << name << "' lacks " << s.variant_key;
    }
    // the section's keys are the union of its variants'
    if (!s.variants.empty())
      for (const Key& k : s.keys) EXPECT_TRUE(used.count(k.name)) << s.path << "." << k.name << " is in no variant";
  }
}

TEST(CaseSchema, EnumsHaveValues) {
  for (const Section& s : sections())
    for (const Key& k : s.keys) {
      if (k.type != Type::kEnum) continue;
      EXPECT_FALSE(k.values.empty()) << s.path << "." << k.name;
      std::set<std::string> seen;
      for (const std::string& v : k.values) {
        EXPECT_FALSE(v.empty()) << s.path << "." << k.name;
        EXPECT_TRUE(seen.insert(v).second) << s.path << "." << k.name << ": '" << v << "' twice";
      }
    }
}

TEST(CaseSchema, RangesAreOrderedAndOnlyOnNumbers) {
  int ranged = 0;
  for (const Section& s : sections())
    for (const Key& k : s.keys) {
      const std::string where = s.path + "." + k.name;
      if (!k.range.defined()) {
        EXPECT_TRUE(k.range_unit.empty()) << where << ": a range unit without a range";
        continue;
      }
      ++ranged;
      EXPECT_TRUE(numeric(k.type)) << where << ": a range on a key that is no number";
      EXPECT_GT(k.range.lo, 0) << where;
      EXPECT_LE(k.range.lo, k.range.hi) << where;
      EXPECT_TRUE(k.range.sign == '+' || k.range.sign == '0' || k.range.sign == '~') << where << ": sign " << k.range.sign;
    }
  EXPECT_GT(ranged, 100);
}

TEST(CaseSchema, RequiredAndDefaultsAreText) {
  // a key's texts are single-line markdown (they become table cells)
  for (const Section& s : sections())
    for (const Key& k : s.keys)
      for (const std::string* t : {&k.type_text, &k.units, &k.def, &k.help})
        EXPECT_EQ(t->find('\n'), std::string::npos) << s.path << "." << k.name;
}

TEST(CaseSchema, ConditionalDefaultsAreTheDependentOnes) {
  // a conditional key has a documented default (that the resolved case does not write); the six
  // whose defaults depend on other keys are marked
  int n = 0;
  for (const Section& s : sections())
    for (const Key& k : s.keys)
      if (k.conditional) {
        ++n;
        EXPECT_FALSE(k.def.empty()) << s.path << "." << k.name << ": conditional without a documented default";
      }
  EXPECT_EQ(n, 6);
  for (const auto& [sec, key] : std::vector<std::pair<std::string, std::string>>{
           {"packing", "insert_structure_after_layer"}, {"fem.meshes.thesis", "dim"}, {"fem.materials", "cohesion"},
           {"fem.materials", "dilation_angle"}, {"fem", "load_steps"}, {"fem", "displacement_steps"}}) {
    const Key* k = find_key(sec + "." + key);
    ASSERT_NE(k, nullptr) << sec << "." << key;
    EXPECT_TRUE(k->conditional) << sec << "." << key;
  }
}

TEST(CaseSchema, SizeDistributionsAgree) {
  // every path read as a size distribution has the same keys and variants
  const Section* a = section_at("particles.generate.size");
  const Section* b = section_at("packing.size");
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(a->variant_key, "distribution");
  EXPECT_EQ(a->variants, b->variants);
  ASSERT_EQ(a->keys.size(), b->keys.size());
  for (std::size_t i = 0; i < a->keys.size(); ++i) EXPECT_EQ(a->keys[i].name, b->keys[i].name);
}
