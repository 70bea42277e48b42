#include <gtest/gtest.h>

#include "core/Error.h"
#include "core/Param.h"

using gis::ParamSet;
using gis::ParamSpec;
using gis::ParamTable;
using gis::ParamType;

namespace {
ParamTable sampleTable() {
    return ParamTable({
        {.name = "vpl_grid", .type = ParamType::Int, .defaultValue = 16, .min = 1, .max = 64, .unit = "VPLs per side",
         .help = "grid"},
        {.name = "radius", .type = ParamType::Float, .defaultValue = 0.1, .min = 0.0, .max = 1.0, .unit = "m",
         .help = "clamp"},
        {.name = "flag", .type = ParamType::Bool, .defaultValue = 1, .help = "switch"},
        {.name = "mode", .type = ParamType::Enum, .defaultValue = 1, .help = "mode", .options = {"a", "b", "c"}},
        {.name = "tau", .type = ParamType::Float, .defaultValue = 0.01, .min = 0.001, .max = 10, .help = "t",
         .logScale = true},
    });
}
} // namespace

TEST(Param, DefaultsComeFromTheTable) {
    ParamSet p(sampleTable());
    EXPECT_EQ(p.getInt("vpl_grid"), 16);
    EXPECT_DOUBLE_EQ(p.getFloat("radius"), 0.1);
    EXPECT_TRUE(p.getBool("flag"));
    EXPECT_EQ(p.getEnum("mode"), "b");
}

TEST(Param, RangeErrorsNameTheParameterRangeUnitAndValue) {
    ParamSet p(sampleTable());
    try {
        p.set("vpl_grid", 100);
        FAIL() << "expected an error";
    } catch (const gis::InputError& e) {
        std::string m = e.what();
        EXPECT_NE(m.find("'vpl_grid'"), std::string::npos) << m;
        EXPECT_NE(m.find("[1, 64]"), std::string::npos) << m;
        EXPECT_NE(m.find("VPLs per side"), std::string::npos) << m;
        EXPECT_NE(m.find("100"), std::string::npos) << m;
    }
    EXPECT_EQ(p.getInt("vpl_grid"), 16) << "a rejected value must not change the set";
    EXPECT_THROW(p.set("vpl_grid", 2.5), gis::InputError);
    EXPECT_THROW(p.set("radius", -0.1), gis::InputError);
    EXPECT_THROW(p.set("radius", "0.5"), gis::InputError);
    EXPECT_THROW(p.set("flag", 1), gis::InputError);
    EXPECT_THROW(p.set("mode", "z"), gis::InputError);
}

TEST(Param, UnknownNamesListTheKnownOnes) {
    ParamSet p(sampleTable());
    try {
        p.set("radus", 0.2, "/params/radus");
        FAIL();
    } catch (const gis::InputError& e) {
        EXPECT_EQ(e.where(), "/params/radus");
        EXPECT_NE(std::string(e.what()).find("radius"), std::string::npos);
    }
}

TEST(Param, StringParsingFollowsTheType) {
    ParamSet p(sampleTable());
    p.setFromString("vpl_grid", "32");
    p.setFromString("radius", "0.25");
    p.setFromString("flag", "false");
    p.setFromString("mode", "c");
    EXPECT_EQ(p.getInt("vpl_grid"), 32);
    EXPECT_DOUBLE_EQ(p.getFloat("radius"), 0.25);
    EXPECT_FALSE(p.getBool("flag"));
    EXPECT_EQ(p.getEnum("mode"), "c");
    EXPECT_THROW(p.setFromString("vpl_grid", "32x"), gis::InputError);
    EXPECT_THROW(p.setFromString("radius", ""), gis::InputError);
}

TEST(Param, ApplyIsAllOrNothing) {
    ParamSet p(sampleTable());
    EXPECT_THROW(p.apply({{"vpl_grid", 8}, {"radius", 5.0}}), gis::InputError);
    EXPECT_EQ(p.getInt("vpl_grid"), 16);
    auto changed = p.apply({{"vpl_grid", 8}, {"radius", 0.1}});
    ASSERT_EQ(changed.size(), 1u);
    EXPECT_EQ(changed[0], "vpl_grid");
}

TEST(Param, SchemaCarriesRangesUnitsAndDefaults) {
    auto schema = sampleTable().jsonSchema();
    EXPECT_EQ(schema["additionalProperties"], false);
    EXPECT_EQ(schema["properties"]["vpl_grid"]["type"], "integer");
    EXPECT_EQ(schema["properties"]["vpl_grid"]["maximum"], 64);
    EXPECT_EQ(schema["properties"]["vpl_grid"]["default"], 16);
    EXPECT_EQ(schema["properties"]["radius"]["x-unit"], "m");
    EXPECT_EQ(schema["properties"]["mode"]["enum"].size(), 3u);
}

TEST(Param, SweepValuesStayInRange) {
    ParamTable t = sampleTable();
    auto ints = ParamTable::sweepValues(*t.find("vpl_grid"), 4);
    ASSERT_EQ(ints.size(), 4u);
    EXPECT_EQ(ints.front(), 1);
    EXPECT_EQ(ints.back(), 64);
    auto logs = ParamTable::sweepValues(*t.find("tau"), 5);
    ASSERT_EQ(logs.size(), 5u);
    EXPECT_NEAR(logs[2].get<double>(), 0.1, 1e-9); // geometric midpoint of [0.001, 10]
    EXPECT_EQ(ParamTable::sweepValues(*t.find("mode"), 9).size(), 3u);
}
