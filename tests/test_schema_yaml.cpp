// The scene schema read from data (pipeline/scene/schema_yaml.h): entries map
// onto KeySpecs the way `hairpipe help scene` shows them, and a malformed
// entry names its keys/<file>:line:column and key.
#include "core/errors.h"
#include "pipeline/scene/schema_yaml.h"
#include "render/view/view.h"
#include "test_support.h"

#include <cmath>

#include <yaml-cpp/yaml.h>

#include <gtest/gtest.h>

using namespace hp;

namespace {

Schema read(const char* text) {
    Schema s;
    readSchemaFile(s, {"t.yaml", text});
    return s;
}

/// Reads `text` expecting a SceneError; returns it.
SceneError readError(const char* text) {
    return test::sceneErrorOf([&] { read(text); }, text);
}

}  // namespace

TEST(SchemaYaml, EntriesBecomeKeySpecsWithNormalisedDefaults) {
    const Schema s = read(R"(
- section: a
  doc: Section a.
- section: a
  doc: Opened again; the first doc wins.
- key: a.n
  type: number
  default: 3.8e9
  range: [0, .inf]
  unit: Pa
  doc: A number.
- key: a.i
  type: integer
  default: 24
  range: [2, 1000]
  doc: An integer.
- key: a.s
  type: string
  doc: 'Text: quoted.'
- key: a.v
  type: vec3
  default: [0, -9.81, 1e-5]
  doc: A vector.
- key: a.c
  type: choice
  default: x
  choices: [x, y]
  doc: A choice.
- key: a.l
  type: list
  default: '[{}]'
  max_items: 16
  doc: A list.
- key: a.f
  type: file
  required: true
  doc: A file.
)");
    ASSERT_EQ(s.sections().size(), 1u);
    EXPECT_EQ(s.sections()[0].doc, "Section a.");
    ASSERT_EQ(s.keys().size(), 7u);
    const KeySpec* n = s.find("a.n");
    ASSERT_TRUE(n);
    EXPECT_EQ(n->type, KeyType::Float);
    EXPECT_EQ(n->defaultYaml, "3800000000");  // %.10g, as the reference page prints it
    EXPECT_EQ(n->min, 0);
    EXPECT_TRUE(std::isinf(n->max));
    EXPECT_EQ(n->unit, "Pa");
    EXPECT_EQ(s.find("a.i")->defaultYaml, "24");
    EXPECT_EQ(s.find("a.i")->min, 2);
    EXPECT_EQ(s.find("a.i")->max, 1000);
    EXPECT_EQ(s.find("a.s")->defaultYaml, "\"\"");  // an absent string default is the empty string
    EXPECT_EQ(s.find("a.s")->doc, "Text: quoted.");
    EXPECT_EQ(s.find("a.v")->defaultYaml, "[0, -9.81, 1e-05]");
    EXPECT_EQ(s.find("a.c")->choices, (std::vector<std::string>{"x", "y"}));
    EXPECT_EQ(s.find("a.l")->defaultYaml, "[{}]");
    EXPECT_EQ(s.find("a.l")->max, 16);
    EXPECT_TRUE(s.find("a.f")->required);
    EXPECT_EQ(s.find("a.f")->defaultYaml, "");
}

TEST(SchemaYaml, MalformedEntriesNameFileLineAndKey) {
    SceneError e = readError("- key: a.n\n  type: number\n  defualt: 1\n  doc: x\n");
    EXPECT_EQ(e.where().file, "keys/t.yaml");
    EXPECT_EQ(e.where().line, 3);
    EXPECT_EQ(e.key(), "a.n");
    EXPECT_NE(std::string(e.what()).find("unknown field `defualt`"), std::string::npos) << e.what();

    e = readError("- key: a.n\n  type: real\n  doc: x\n");
    EXPECT_EQ(e.where().line, 2);
    EXPECT_NE(std::string(e.what()).find("`type` must be one of"), std::string::npos) << e.what();

    e = readError("- key: a.n\n  type: number\n");
    EXPECT_NE(std::string(e.what()).find("needs `doc`"), std::string::npos) << e.what();

    e = readError("- key: a.i\n  type: integer\n  default: 2.5\n  doc: x\n");
    EXPECT_EQ(e.where().line, 3);
    EXPECT_NE(std::string(e.what()).find("must be whole"), std::string::npos) << e.what();

    e = readError("- key: a.v\n  type: vec3\n  default: [1, 2]\n  doc: x\n");
    EXPECT_NE(std::string(e.what()).find("[x, y, z]"), std::string::npos) << e.what();

    e = readError("- key: a.c\n  type: choice\n  doc: x\n");
    EXPECT_NE(std::string(e.what()).find("needs `choices`"), std::string::npos) << e.what();

    e = readError("- key: a.b\n  type: bool\n  doc: x\n- key: a.b\n  type: bool\n  doc: y\n");
    EXPECT_EQ(e.where().line, 4);
    EXPECT_NE(std::string(e.what()).find("given twice"), std::string::npos) << e.what();

    e = readError("- key: a.b\n  type: bool\n  doc: [x\n");
    EXPECT_EQ(e.where().file, "keys/t.yaml");
    EXPECT_GT(e.where().line, 0);
}

TEST(SchemaYaml, EveryCompiledInFileIsReadInTheListedOrder) {
    const Schema& scene = Schema::scene();
    size_t keys = 0;
    for (const SchemaFile& f : embeddedSceneKeyFiles()) {
        Schema one;
        ASSERT_NO_THROW(readSchemaFile(one, f)) << f.name;
        EXPECT_FALSE(one.keys().empty()) << f.name;
        keys += one.keys().size();
    }
    EXPECT_EQ(keys, scene.keys().size());  // no file left out of schema.cpp's order
    EXPECT_GT(embeddedSceneKeyFiles().size(), 10u);
}

TEST(SchemaYaml, LightDefaultIsTheThreePointRig) {
    const KeySpec* lights = Schema::scene().find("render.lights");
    ASSERT_TRUE(lights);
    const YAML::Node list = YAML::Load(lights->defaultYaml);
    const std::vector<Light> rig = threePointRig();
    ASSERT_EQ(list.size(), rig.size());
    for (size_t i = 0; i < rig.size(); ++i) {
        EXPECT_FLOAT_EQ(list[i]["intensity"].as<float>(), rig[i].intensity);
        EXPECT_FLOAT_EQ(list[i]["direction"][1].as<float>(), rig[i].direction.y());
        EXPECT_EQ(list[i]["shadows"] ? list[i]["shadows"].as<bool>() : true, rig[i].castsShadows);
    }
}
