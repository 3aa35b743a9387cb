#include "pipeline/scene/scene.h"
#include "pipeline/scene/schema.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <sstream>

using namespace hp;

namespace {

/// Parses `yaml` expecting a SceneError; returns it.
SceneError parseError(const std::string& yaml, const std::vector<std::string>& sets = {}) {
    return test::sceneErrorOf([&] { Scene::parse(yaml, "shot.yaml", ".", sets); }, yaml);
}

}  // namespace

TEST(Scene, DefaultsFillAbsentKeys) {
    const Scene s = Scene::parse("fps: 30\n", "shot.yaml", ".");
    EXPECT_EQ(s.number("fps"), 30.0);
    EXPECT_TRUE(s.given("fps"));
    EXPECT_EQ(s.integer("seed"), 1);
    EXPECT_FALSE(s.given("seed"));
    EXPECT_EQ(s.frames("frames").front(), 1);
}

TEST(Scene, WrongTypeNamesLineColumnAndKey) {
    const SceneError e = parseError("frames: 1-10\nfps: fast\n");
    EXPECT_EQ(e.where().file, "shot.yaml");
    EXPECT_EQ(e.where().line, 2);
    EXPECT_EQ(e.where().column, 6);
    EXPECT_EQ(e.key(), "fps");
    EXPECT_NE(std::string(e.what()).find("shot.yaml:2:6: 'fps': expected a number"), std::string::npos) << e.what();
}

TEST(Scene, OutOfRangeIsRejected) {
    const SceneError e = parseError("fps: 0\n");
    EXPECT_EQ(e.key(), "fps");
    EXPECT_NE(e.detail().find("must be in [1, 1000]"), std::string::npos) << e.what();
}

TEST(Scene, IntegerRejectsFraction) {
    const SceneError e = parseError("seed: 1.5\n");
    EXPECT_NE(e.detail().find("expected an integer"), std::string::npos) << e.what();
}

TEST(Scene, NonFiniteNumbersAreRejected) {
    for (const char* v : {"nan", "inf", "-inf", "1e999"}) {
        const SceneError e = parseError(std::string("fps: ") + v + "\n");
        EXPECT_NE(e.detail().find("finite"), std::string::npos) << v << ": " << e.what();
    }
}

TEST(Scene, UnknownKeySuggestsTheClosest) {
    const SceneError e = parseError("fps: 24\nframse: 1-3\n");
    EXPECT_EQ(e.where().line, 2);
    EXPECT_EQ(e.where().column, 1);
    EXPECT_EQ(e.key(), "framse");
    EXPECT_NE(std::string(e.what()).find("did you mean 'frames'"), std::string::npos) << e.what();
}

TEST(Scene, UnknownNestedKey) {
    const SceneError e = parseError("output:\n  directroy: x\n");
    EXPECT_EQ(e.key(), "output.directroy");
    EXPECT_EQ(e.where().line, 2);
    EXPECT_NE(std::string(e.what()).find("did you mean 'directory'"), std::string::npos) << e.what();
}

TEST(Scene, SectionMustBeAMap) {
    const SceneError e = parseError("output: 3\n");
    EXPECT_EQ(e.key(), "output");
    EXPECT_NE(e.detail().find("section"), std::string::npos);
}

TEST(Scene, DuplicateKey) {
    const SceneError e = parseError("fps: 24\nfps: 25\n");
    EXPECT_EQ(e.where().line, 2);
    EXPECT_NE(e.detail().find("duplicate"), std::string::npos);
}

TEST(Scene, YamlSyntaxErrorHasLocation) {
    const SceneError e = parseError("fps: 24\nframes: [1, 2\n");
    EXPECT_GE(e.where().line, 2);
    EXPECT_NE(e.detail().find("YAML syntax error"), std::string::npos) << e.what();
}

TEST(Scene, BadFrameRangeInFile) {
    const SceneError e = parseError("frames: 10-1\n");
    EXPECT_EQ(e.key(), "frames");
    EXPECT_EQ(e.where().line, 1);
    EXPECT_NE(e.detail().find("ends before it starts"), std::string::npos) << e.what();
}

TEST(Scene, SetOverridesAreTypedAndValidated) {
    const Scene s = Scene::parse("fps: 24\n", "shot.yaml", ".", {"fps=48", "seed=7", "frames=3-5"});
    EXPECT_EQ(s.number("fps"), 48.0);
    EXPECT_EQ(s.integer("seed"), 7);
    EXPECT_EQ(s.frames("frames"), (std::vector<int>{3, 4, 5}));
    EXPECT_EQ(s.where("fps").file, "--set fps=48");

    const SceneError bad = parseError("", {"seed=abc"});
    EXPECT_EQ(bad.key(), "seed");
    EXPECT_NE(std::string(bad.what()).find("--set seed=abc"), std::string::npos) << bad.what();
    EXPECT_NE(bad.detail().find("expected an integer"), std::string::npos);

    const SceneError unknown = parseError("", {"fsp=3"});
    EXPECT_NE(std::string(unknown.what()).find("did you mean 'fps'"), std::string::npos) << unknown.what();

    const SceneError malformed = parseError("", {"fps"});
    EXPECT_NE(malformed.detail().find("key.path=value"), std::string::npos);
}

TEST(Scene, EmptySetValueIsTheEmptyStringForTextKeys) {
    // "--set reference.png=" turns the PNG off (the key's doc: empty writes
    // none); before, YAML read the empty value as null, "has no value".
    const Scene s = Scene::parse("reference: {png: out.png}\n", "shot.yaml", ".", {"reference.png=", "cache.usd= "});
    EXPECT_EQ(s.text("reference.png"), "");
    EXPECT_TRUE(s.given("reference.png"));
    EXPECT_EQ(s.where("reference.png").file, "--set reference.png=");
    EXPECT_EQ(s.text("cache.usd"), "") << "blanks only are empty too";
    EXPECT_EQ(Scene::parse("", "shot.yaml", ".", {"reference.png=\"\""}).text("reference.png"), "")
        << "the quoted spelling still works";
    // A file key without a file is "none" unless the key is required.
    EXPECT_TRUE(Scene::parse("", "shot.yaml", ".", {"hair.groom.file="}).file("hair.groom.file").empty());
    // Keys that are not text still need a value.
    for (const char* set : {"fps=", "render.camera.width=", "render.exposure=", "simulation.preload="}) {
        const SceneError e = parseError("", {set});
        EXPECT_NE(e.detail().find("has no value"), std::string::npos) << set << ": " << e.what();
    }
}

TEST(Scene, FileKeysMustExist) {
    test::TempDir dir;
    test::writeFile(dir / "scene.yaml", "output:\n  directory: out\n");
    const Scene s = Scene::load(dir / "scene.yaml");
    EXPECT_EQ(s.text("output.directory"), "out");
    EXPECT_THROW(Scene::load(dir / "missing.yaml"), AssetError);
}

TEST(Scene, CurveParsesScalarsAndKeys) {
    Curve c;
    c.keys = {{1, 0.0}, {11, 1.0}};
    EXPECT_DOUBLE_EQ(c.eval(0), 0.0);
    EXPECT_DOUBLE_EQ(c.eval(6), 0.5);
    EXPECT_DOUBLE_EQ(c.eval(20), 1.0);
}

TEST(Scene, DumpMarksDefaults) {
    const Scene s = Scene::parse("fps: 30\n", "shot.yaml", ".");
    const std::string d = s.dump();
    EXPECT_NE(d.find("fps: 30\n"), std::string::npos) << d;
    EXPECT_NE(d.find("seed: 1    # default"), std::string::npos) << d;
}

TEST(Schema, EveryKeyIsDocumented) {
    for (const KeySpec& k : Schema::scene().keys()) {
        EXPECT_FALSE(k.doc.empty()) << k.path;
        if (k.type == KeyType::Enum) {
            EXPECT_FALSE(k.choices.empty()) << k.path;
        }
    }
}

TEST(Schema, DefaultsAreValidAndFillAnEmptyScene) {
    // Every default must pass its own validation (an empty scene uses them
    // all), and every key of an empty scene must read back as its schema
    // default, marked as not given: the same value a --set of the default's
    // text gives (keys inside list items are checked by SceneLists).
    const Scene empty = Scene::parse("", "empty.yaml", ".");
    size_t checked = 0;
    for (const KeySpec& k : Schema::scene().keys()) {
        if (k.type == KeyType::List || k.path.find("[]") != std::string::npos) continue;
        SCOPED_TRACE(k.path + " (default '" + k.defaultYaml + "')");
        if (k.defaultYaml.empty()) {
            EXPECT_FALSE(empty.has(k.path)) << "a key without default is absent";
            continue;
        }
        ASSERT_TRUE(empty.has(k.path));
        EXPECT_FALSE(empty.given(k.path));
        const Scene set = Scene::parse("", "set.yaml", ".", {k.path + "=" + k.defaultYaml});
        ASSERT_TRUE(set.given(k.path));
        switch (k.type) {
        case KeyType::Bool: EXPECT_EQ(empty.flag(k.path), set.flag(k.path)); break;
        case KeyType::Int: EXPECT_EQ(empty.integer(k.path), set.integer(k.path)); break;
        case KeyType::Float: EXPECT_EQ(empty.number(k.path), set.number(k.path)); break;
        case KeyType::String:
        case KeyType::Enum: EXPECT_EQ(empty.text(k.path), set.text(k.path)); break;
        case KeyType::Vec3: EXPECT_EQ(empty.vec3(k.path), set.vec3(k.path)); break;
        case KeyType::FrameRange: EXPECT_EQ(empty.frames(k.path), set.frames(k.path)); break;
        case KeyType::Curve: EXPECT_EQ(empty.curve(k.path).keys, set.curve(k.path).keys); break;
        default: continue;  // files resolve against different folders in a file and on the command line
        }
        ++checked;
    }
    EXPECT_GT(checked, 100u) << "the schema's keys were walked";
}

TEST(Schema, ReferencePageIsUpToDate) {
    const std::string committed = test::readFile(test::sourcePath("docs/scene-reference.md"));
    EXPECT_EQ(committed, Schema::scene().markdown())
        << "docs/scene-reference.md is stale: regenerate it with 'hairpipe help scene > docs/scene-reference.md'";
}

#include "pipeline/scene/view_settings.h"
#include "render/reference/hair_bsdf.h"
#include "render/reference/hair_fit.h"

TEST(SceneLists, DefaultListAndItemDefaults) {
    const Scene s = Scene::parse("", "shot.yaml", ".");
    // The default list is the three-point rig of render/view/view.cpp.
    ASSERT_EQ(s.count("render.lights"), 3u);
    EXPECT_EQ(s.text("render.lights[0].type"), "directional");
    EXPECT_EQ(s.text("render.lights[0].space"), "camera");
    for (size_t i = 0; i < 3; ++i) EXPECT_TRUE(s.flag(cat("render.lights[", i, "].shadows"))) << i;
    const View v = makeView(s);
    const std::vector<Light> rig = threePointRig();
    ASSERT_EQ(v.lights.size(), rig.size());
    for (size_t i = 0; i < rig.size(); ++i) {
        EXPECT_TRUE(v.lights[i].direction.isApprox(rig[i].direction, 1e-5f)) << i;
        EXPECT_NEAR(v.lights[i].intensity, rig[i].intensity, 1e-6f) << i;
        EXPECT_EQ(v.lights[i].castsShadows, rig[i].castsShadows) << i;
        EXPECT_TRUE(v.lights[i].cameraRelative) << i;
    }
}

// The preview shadows at most preview.shadow.max_lights lights; the view
// both renderers get marks the rest unshadowed, so the Kajiya-Kay reference
// shadows exactly the preview's lights.
TEST(SceneLists, ShadowedLightsAreCappedByThePreview) {
    const std::string lights = "render:\n  lights:\n    - {shadows: false}\n    - {}\n    - {}\n    - {}\n"
                               "    - {}\n    - {}\n";
    auto shadowed = [&](const std::string& more) {
        std::vector<bool> out;
        for (const Light& l : makeView(Scene::parse(lights + more, "shot.yaml", ".")).lights)
            out.push_back(l.castsShadows);
        return out;
    };
    EXPECT_EQ(shadowed(""), (std::vector<bool>{false, true, true, true, true, false}));
    EXPECT_EQ(shadowed("preview: {shadow: {max_lights: 2}}"), (std::vector<bool>{false, true, true, false, false, false}));
    EXPECT_EQ(shadowed("preview: {shadow: {max_lights: 0}}"), (std::vector<bool>(6, false)));
}

TEST(SceneLists, ItemsFromFileGetDefaultsAndLocations) {
    const Scene s = Scene::parse("render:\n  lights:\n    - type: point\n      position: [0, 2, 0]\n    - intensity: 7\n",
                                 "shot.yaml", ".");
    ASSERT_EQ(s.count("render.lights"), 2u);
    EXPECT_EQ(s.text("render.lights[0].type"), "point");
    EXPECT_EQ(s.text("render.lights[1].type"), "directional") << "item keys take their defaults";
    EXPECT_EQ(s.number("render.lights[1].intensity"), 7.0);
    EXPECT_EQ(s.where("render.lights[1].intensity").line, 5);
}

TEST(SceneLists, ItemErrorsNameTheIndex) {
    const SceneError e = parseError("render:\n  lights:\n    - type: spot\n");
    EXPECT_EQ(e.key(), "render.lights[0].type");
    EXPECT_EQ(e.where().line, 3);
    EXPECT_NE(e.detail().find("expected one of directional, point"), std::string::npos) << e.what();
    const SceneError notMap = parseError("render:\n  lights: [3]\n");
    EXPECT_EQ(notMap.key(), "render.lights[0]");
}

TEST(SceneLists, SetOverridesItemsAndWholeLists) {
    const Scene a = Scene::parse("", "shot.yaml", ".", {"render.lights[0].intensity=5"});
    EXPECT_EQ(a.number("render.lights[0].intensity"), 5.0);
    const Scene b = Scene::parse("", "shot.yaml", ".", {"render.lights=[{type: point}, {type: point}]"});
    EXPECT_EQ(b.count("render.lights"), 2u);
    EXPECT_EQ(b.text("render.lights[1].type"), "point");
    const SceneError e = parseError("", {"render.lights[3].intensity=1"});
    EXPECT_NE(e.detail().find("has only 3 items"), std::string::npos) << e.what();
}

TEST(SceneLists, TooManyItems) {
    std::string yaml = "render:\n  lights:\n";
    for (int i = 0; i < 17; ++i) yaml += "    - {type: point}\n";
    const SceneError e = parseError(yaml);
    EXPECT_NE(e.detail().find("at most 16"), std::string::npos) << e.what();
}

TEST(ViewSettings, DisplayAndMelaninKeys) {
    const Scene s = Scene::parse(
        "render:\n  exposure: 1.5\n  background: {type: gradient, color: [0.2, 0.2, 0.2]}\n"
        "  hair: {melanin: 1.3, pheomelanin: 0.2}\n",
        "shot.yaml", ".");
    const DisplaySettings d = makeDisplaySettings(s);
    EXPECT_EQ(d.exposure, 1.5f);
    EXPECT_EQ(d.backdrop.kind, Backdrop::Kind::Gradient);
    EXPECT_TRUE(d.backdrop.top.isApprox(Vec3f(0.2f, 0.2f, 0.2f)));
    // One key drives both renderers: the physical σa and the preview's
    // material fitted to that fibre (render.hair.shading: fitted, the default)...
    const View v = makeView(s);
    EXPECT_TRUE(hairAbsorption(s).isApprox(hairAbsorptionFromMelanin(1.3f, 0.2f)));
    EXPECT_TRUE(hairFiber(s).sigmaA.isApprox(hairAbsorptionFromMelanin(1.3f, 0.2f)));
    EXPECT_EQ(v.hair.shading, HairShading::Fitted);
    HairMaterial fitted;
    fitHairMaterial(hairFiber(s), &fitted);
    EXPECT_TRUE(v.hair.color.isApprox(fitted.color));
    EXPECT_TRUE(v.hair.tt.strength[0].isApprox(fitted.tt.strength[0]));
    EXPECT_FLOAT_EQ(v.hair.transmittance, fitted.dual.forward.dot(Vec3f(0.2126f, 0.7152f, 0.0722f)));
    // ...or, in shading kajiya-kay, the Kajiya-Kay colour through Chiang's colour fit.
    const Scene kk = Scene::parse("render:\n  hair: {melanin: 1.3, pheomelanin: 0.2, shading: kajiya-kay}\n", "shot.yaml", ".");
    const View vk = makeView(kk);
    EXPECT_EQ(vk.hair.shading, HairShading::KajiyaKay);
    EXPECT_TRUE(vk.hair.color.isApprox(hairColorFromAbsorption(hairAbsorptionFromMelanin(1.3f, 0.2f), 0.3f)));
    EXPECT_FLOAT_EQ(vk.hair.transmittance, 0.8f);
    // A view the built-in transform does not know names the key and its line.
    const Scene bad = Scene::parse("render:\n  ocio:\n    view: nope\n", "shot.yaml", ".");
    try {
        makeDisplaySettings(bad);
        FAIL() << "an unknown view must be a scene error";
    } catch (const SceneError& e) {
        EXPECT_EQ(e.key(), "render.ocio.view");
        EXPECT_EQ(e.where().line, 3);
        EXPECT_NE(std::string(e.what()).find("nope"), std::string::npos) << e.what();
    }
}

TEST(ViewSettings, MapsKeysAndChecksAcrossThem) {
    const Scene s = Scene::parse("render:\n  camera: {width: 320, height: 240, fov: 30}\n", "shot.yaml", ".");
    const View v = makeView(s);
    EXPECT_EQ(v.camera.width, 320);
    EXPECT_EQ(v.camera.fovY, 30.f);
    ASSERT_EQ(v.lights.size(), 3u);
    // Camera-relative: the key comes from the camera's upper left.
    const std::vector<Light> world = v.worldLights();
    const Vec3f toKey = -world[0].direction.normalized();
    const Vec3f right = (v.camera.target - v.camera.position).cross(v.camera.up).normalized();
    EXPECT_LT(toKey.dot(right), 0.f);
    EXPECT_GT(toKey.dot(v.camera.up), 0.f);
    const Scene bad = Scene::parse("render:\n  camera: {position: [0, 0, 0]}\n", "shot.yaml", ".");
    try {
        makeView(bad);
        FAIL();
    } catch (const SceneError& e) {
        EXPECT_EQ(e.key(), "render.camera.target");
    }
}

namespace {

/// The render block scenes/default.yaml carried before its look became the
/// keys' defaults (commit 2e3b0a3), written out as it was: the reference the
/// defaults must reproduce.
const char* kDefaultShotLook =
    "render:\n"
    "  camera: {mode: follow, hair: cache, fov: 38, width: 560, height: 720, margin: 0.04}\n"
    "  ocio: {view: filmic}\n"
    "  exposure: 0\n"
    "  background: {type: gradient, color: [0.09, 0.09, 0.1], bottom: [0.025, 0.025, 0.028]}\n"
    "  hair: {melanin: 0.3, pheomelanin: 0.1, ks: 0.12}\n";

/// Every resolved render.* value of `s` ("key: value" lines of Scene::dump
/// without the default marker). Without an OCIO config the empty view is the
/// built-in filmic view (render/image/display_transform.cpp), so it is
/// compared as such.
std::vector<std::string> resolvedLook(const Scene& s) {
    std::vector<std::string> lines;
    std::istringstream in(s.dump());
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("render.", 0) != 0) continue;
        line = line.substr(0, line.find("    # default"));
        if (line == "render.ocio.view: \"\"") line = "render.ocio.view: \"filmic\"";
        lines.push_back(line);
    }
    return lines;
}

}  // namespace

TEST(Look, SceneWithoutRenderKeysResolvesToTheDefaultShotsLook) {
    const Scene none = Scene::parse("", "none.yaml", ".");
    const Scene shot = Scene::parse(kDefaultShotLook, "look.yaml", ".");
    const std::vector<std::string> a = resolvedLook(none), b = resolvedLook(shot);
    ASSERT_GT(a.size(), 50u) << "the render keys were read";
    EXPECT_EQ(a, b);
    // The same through the settings the renderers get.
    const View va = makeView(none), vb = makeView(shot);
    EXPECT_EQ(va.camera.width, 560);
    EXPECT_EQ(va.camera.height, 720);
    EXPECT_EQ(va.camera.fovY, vb.camera.fovY);
    EXPECT_TRUE(va.hair.color.isApprox(vb.hair.color));
    EXPECT_TRUE(hairAbsorption(none).isApprox(hairAbsorptionFromMelanin(0.3f, 0.1f)));
    const DisplaySettings da = makeDisplaySettings(none);
    EXPECT_EQ(da.backdrop.kind, Backdrop::Kind::Gradient);
    EXPECT_TRUE(da.backdrop.top.isApprox(Vec3f(0.09f, 0.09f, 0.1f)));
    EXPECT_TRUE(da.backdrop.bottom.isApprox(Vec3f(0.025f, 0.025f, 0.028f)));
    EXPECT_EQ(da.exposure, 0.f);
}

TEST(Look, DefaultSceneGivesNoRenderKey) {
    // The demo's look is the defaults: scenes/default.yaml sets no render key,
    // so what it shows is what any scene without render keys gets.
    const Scene s = Scene::load(test::sourcePath("scenes/default.yaml"));
    size_t checked = 0;
    for (const KeySpec& k : Schema::scene().keys()) {
        if (k.path.rfind("render.", 0) != 0 || k.path.find("[]") != std::string::npos) continue;
        EXPECT_FALSE(s.given(k.path)) << k.path;
        ++checked;
    }
    EXPECT_GT(checked, 40u) << "the render keys outside lists";
    EXPECT_EQ(resolvedLook(s), resolvedLook(Scene::parse(kDefaultShotLook, "look.yaml", ".")));
}

TEST(Look, OtherFibreKeysAreRefusedWhileMelaninIsSet) {
    // render.hair.melanin is set by default: the physical fibre's own pigment
    // keys and the colour inversion would be silently ignored, so giving them
    // is an error naming the key, unless render.hair.melanin is -1.
    for (const char* key : {"reference.physical.melanin=8", "reference.physical.pheomelanin=1",
                            "reference.physical.use_hair_color=true"}) {
        const Scene s = Scene::parse("", "shot.yaml", ".", {key});
        const SceneError e = test::sceneErrorOf([&] { makeView(s); }, key);
        EXPECT_EQ(e.key(), std::string(key).substr(0, std::string(key).find('='))) << e.what();
        EXPECT_NE(std::string(e.what()).find("render.hair.melanin: -1"), std::string::npos) << e.what();
    }
    const Scene off = Scene::parse("render:\n  hair: {melanin: -1}\nreference:\n  physical: {melanin: 8}\n",
                                   "shot.yaml", ".");
    EXPECT_TRUE(hairAbsorption(off).isApprox(hairAbsorptionFromMelanin(8.f, 0.f)));
}
