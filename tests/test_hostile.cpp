// The hostile-input catalogue (issue 12): what artists and farms throw at
// the hairpipe executable. Each case runs the real binary and checks the exit
// code (1: the input is wrong; the run never starts), the message (file,
// line, key, what is wrong) and that nothing was left in the output folder.
// Under the sanitizer build a memory error exits 86, so "exit 1" also means
// "no crash".
#include "core/errors.h"
#include "pipeline/scene/scene.h"
#include "pipeline/batch/strand_cache.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <fstream>

namespace fs = std::filesystem;
using namespace hp::test;

namespace {

/// Expects exit code 1 and every `needles` substring in the output.
void expectRejected(const ProcessResult& r, std::initializer_list<const char*> needles) {
    EXPECT_EQ(r.exitCode, 1) << r.output;
    for (const char* n : needles) EXPECT_NE(r.output.find(n), std::string::npos) << "missing '" << n << "' in\n" << r.output;
}

/// In-process twin of a `validate` run (same loader, same message), for the
/// long tables; each table also goes through the binary once.
std::string loadError(const std::filesystem::path& file) {
    try {
        hp::Scene::load(file);
    } catch (const hp::Error& e) {
        return e.what();
    }
    return "(loaded without error)";
}

/// Each case's YAML, written to `file`, fails to load with a message that
/// contains the case's text.
template <size_t N>
void expectLoadErrors(const std::filesystem::path& file, const std::pair<const char*, const char*> (&cases)[N]) {
    for (const auto& [yaml, message] : cases) {
        writeFile(file, yaml);
        const std::string error = loadError(file);
        EXPECT_NE(error.find(message), std::string::npos) << error;
    }
}

/// Number of files (of any kind) under `dir`; 0 if it does not exist.
size_t filesUnder(const fs::path& dir) {
    std::error_code ec;
    if (!fs::exists(dir, ec)) return 0;
    size_t n = 0;
    for (auto it = fs::recursive_directory_iterator(dir); it != fs::recursive_directory_iterator(); ++it)
        if (!it->is_directory()) ++n;
    return n;
}

/// A small simulated shot around `head` (a file name in the test folder).
/// These meshes are not head-shaped, so every triangle is scalp (the
/// default, a cap over the top and back of a head, may select none).
std::string shotWithHead(const std::string& head, const std::string& extra = "") {
    return "frames: 1-2\nhead: {file: " + head + ", scalp: {method: all}}\nhair:\n  guides: {count: 6, segments: 4}\n"
           "  followers: {count: 10}\n" + extra;
}

}  // namespace

TEST(Hostile, EmptyAndCommentOnlySceneFiles) {
    TempDir dir;
    writeFile(dir / "empty.yaml", "");
    expectRejected(runHairpipe("validate empty.yaml", dir.path()), {"empty.yaml: scene file is empty"});
    writeFile(dir / "comments.yaml", "# a scene\n\n   # nothing else\n");
    expectRejected(runHairpipe("run comments.yaml --out out", dir.path()), {"comments.yaml: scene file is empty"});
    EXPECT_EQ(filesUnder(dir / "out"), 0u);
}

TEST(Hostile, BinarySceneFile) {
    TempDir dir;
    std::string bytes = "frames: 1-3\n";
    for (int i = 0; i < 4096; ++i) bytes += char((i * 131 + 7) & 0xff);
    writeFile(dir / "binary.yaml", bytes);
    expectRejected(runHairpipe("validate binary.yaml", dir.path()), {"binary.yaml: is not a text file (a NUL byte at offset"});
    // Without NUL bytes the YAML parser reports where the garbage starts.
    writeFile(dir / "garbage.yaml", "frames: 1-3\n\"\\\xff\xfe\n");
    expectRejected(runHairpipe("validate garbage.yaml", dir.path()), {"garbage.yaml:2:", "YAML syntax error"});
}

TEST(Hostile, HugeSceneFileIsRefusedUnread) {
    TempDir dir;
    {
        // 50 MB, sparse: refused by its size before a byte is read.
        std::ofstream out(dir / "huge.yaml", std::ios::binary);
        out << "frames: 1-3\n";
        out.seekp(50 << 20);
        out << '\n';
    }
    expectRejected(runHairpipe("validate huge.yaml", dir.path()),
                   {"huge.yaml: scene file is 52428801 bytes; scenes over 16777216 bytes are refused"});
}

TEST(Hostile, DeeplyNestedYaml) {
    TempDir dir;
    // yaml-cpp parses recursively: 100k levels would overflow the stack.
    writeFile(dir / "flow.yaml", "frames: " + std::string(100000, '[') + std::string(100000, ']') + "\n");
    expectRejected(runHairpipe("validate flow.yaml", dir.path()), {"flow.yaml:1:", "YAML nested too deeply"});
    std::string block;
    for (int i = 0; i < 3000; ++i) block += std::string(size_t(i), ' ') + "k" + std::to_string(i) + ":\n";
    writeFile(dir / "block.yaml", block);
    expectRejected(runHairpipe("validate block.yaml", dir.path()), {"block.yaml:", "YAML nested too deeply"});
    // Nested within the depth limit but under a key that is not a section.
    writeFile(dir / "map.yaml", "fps: {a: {b: {c: 1}}}\n");
    expectRejected(runHairpipe("validate map.yaml", dir.path()), {"map.yaml:1:6: 'fps': expected a number, got a map"});
}

TEST(Hostile, NanAndInfinityInNumericKeys) {
    TempDir dir;
    const std::pair<const char*, const char*> cases[] = {
        {"fps: .nan\n", "n.yaml:1:6: 'fps': must be a finite number, got '.nan'"},
        {"fps: nan\n", "n.yaml:1:6: 'fps': must be a finite number, got 'nan'"},
        {"hair:\n  guides:\n    length: .inf\n", "n.yaml:3:13: 'hair.guides.length': must be a finite number, got '.inf'"},
        {"hair:\n  guides:\n    length: -.Inf\n", "'hair.guides.length': must be a finite number, got '-.Inf'"},
        {"head:\n  translate: [0, inf, 0]\n", "n.yaml:2:18: 'head.translate': must be a finite number, got 'inf'"},
        {"fps: 1e999\n", "n.yaml:1:6: 'fps': must be a finite number, got '1e999'"},
        {"render:\n  camera:\n    fov: NaN\n", "'render.camera.fov': must be a finite number"},
    };
    expectLoadErrors(dir / "n.yaml", cases);
    writeFile(dir / "n.yaml", cases[0].first);
    expectRejected(runHairpipe("validate n.yaml", dir.path()), {cases[0].second});
}

TEST(Hostile, NegativeAndZeroCounts) {
    TempDir dir;
    const std::pair<const char*, const char*> cases[] = {
        {"hair:\n  guides:\n    count: -5\n", "z.yaml:3:12: 'hair.guides.count': must be in [0, 1000000]"},
        {"hair:\n  followers:\n    count: -1\n", "z.yaml:3:12: 'hair.followers.count': must be in [0, 10000000]"},
        {"hair:\n  guides:\n    segments: 0\n", "z.yaml:3:15: 'hair.guides.segments': must be in [1, 200]"},
        {"fps: 0\n", "z.yaml:1:6: 'fps': must be in"},
        {"render:\n  camera:\n    width: 0\n", "z.yaml:3:12: 'render.camera.width': must be in [16, 16384] px"},
        {"frames: 5-1\n", "z.yaml:1:9: 'frames': bad frame range '5-1': '5-1' ends before it starts"},
    };
    expectLoadErrors(dir / "z.yaml", cases);
    writeFile(dir / "z.yaml", cases[0].first);
    expectRejected(runHairpipe("validate z.yaml", dir.path()), {cases[0].second});
}

TEST(Hostile, AbsurdSizesAreRejectedAtLoad) {
    TempDir dir;
    const std::pair<const char*, const char*> cases[] = {
        {"hair:\n  followers:\n    count: 1000000000\n", "a.yaml:3:12: 'hair.followers.count': must be in [0, 10000000]"},
        {"hair:\n  guides:\n    segments: 1000000\n", "a.yaml:3:15: 'hair.guides.segments': must be in [1, 200]"},
        {"render:\n  camera:\n    width: 100000\n    height: 100000\n", "a.yaml:3:12: 'render.camera.width': must be in [16, 16384] px"},
        // Each in range, the products are not (budget.*).
        {"hair:\n  guides:\n    count: 1000000\n    segments: 200\n",
         "a.yaml:3:12: 'hair.guides.count': simulated guide vertices (hair.guides.count × vertices per strand) would "
         "be 2.01e+08, over the budget of 5e+06 (budget.guide_vertices"},
        {"hair:\n  followers:\n    count: 10000000\n  guides:\n    segments: 100\n",
         "a.yaml:3:12: 'hair.followers.count': strand vertices per frame"},
        {"render:\n  camera: {width: 16384, height: 16384}\nreference: {scale: 4}\n",
         "'render.camera.width': reference pixels (width × height × reference.scale²) would be 4.29497e+09"},
        {"render:\n  camera: {width: 8192, height: 8192}\nreference: {samples: 4096}\n",
         "a.yaml:3:22: 'reference.samples': reference camera samples per frame"},
    };
    expectLoadErrors(dir / "a.yaml", cases);
    // Through the binary, with `run`: the scene is refused before an output
    // folder or any stage exists.
    for (size_t i : {size_t(0), size_t(3)}) {
        writeFile(dir / "a.yaml", cases[i].first);
        expectRejected(runHairpipe("run a.yaml --out out", dir.path()), {cases[i].second});
        EXPECT_FALSE(fs::exists(dir / "out"));
    }
    // A bigger machine raises the budget.
    writeFile(dir / "a.yaml", "hair:\n  guides:\n    count: 1000000\n    segments: 200\nbudget:\n  guide_vertices: 3e8\n  strand_vertices: 3e8\n");
    EXPECT_EQ(runHairpipe("validate a.yaml", dir.path()).exitCode, 0);
}

TEST(Hostile, HeadWithoutTriangles) {
    TempDir dir;
    writeFile(dir / "lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n");
    writeFile(dir / "s.yaml", shotWithHead("lines.obj"));
    expectRejected(runHairpipe("sim s.yaml --out out", dir.path()),
                   {"lines.obj: contains no triangle mesh (only points or lines)"});
    writeFile(dir / "empty.obj", "");
    writeFile(dir / "s.yaml", shotWithHead("empty.obj"));
    expectRejected(runHairpipe("sim s.yaml --out out", dir.path()), {"empty.obj: "});
    writeFile(dir / "junk.glb", std::string("glTF\x02\0\0\0", 8) + std::string(64, '\x7f'));
    writeFile(dir / "s.yaml", shotWithHead("junk.glb"));
    expectRejected(runHairpipe("sim s.yaml --out out", dir.path()), {"junk.glb: cannot read it as a mesh file"});
    EXPECT_EQ(filesUnder(dir / "out"), 0u);
}

TEST(Hostile, DegenerateTriangles) {
    TempDir dir;
    // Only zero-area triangles: no scalp area to grow roots on.
    writeFile(dir / "flat.obj", "v 0 0 0\nv 0.1 0 0\nv 0.2 0 0\nv 0.3 0 0\nf 1 2 3\nf 2 3 4\n");
    writeFile(dir / "s.yaml", shotWithHead("flat.obj"));
    expectRejected(runHairpipe("sim s.yaml --out out", dir.path()),
                   {"s.yaml:2:", "'head.file': the scalp (2 triangles) has zero area in", "only degenerate triangles"});
    EXPECT_EQ(filesUnder(dir / "out"), 0u);
    // Degenerate triangles beside good ones are harmless: hair grows on the
    // rest. An octahedron of radius 0.1 m plus two zero-area triangles.
    writeFile(dir / "mixed.obj",
              "v 0.1 0 0\nv -0.1 0 0\nv 0 0.1 0\nv 0 -0.1 0\nv 0 0 0.1\nv 0 0 -0.1\n"
              "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n"
              "f 1 1 3\nf 5 5 5\n");
    writeFile(dir / "s.yaml", shotWithHead("mixed.obj"));
    const ProcessResult ok = runHairpipe("sim s.yaml --out out", dir.path());
    EXPECT_EQ(ok.exitCode, 0) << ok.output;
    EXPECT_TRUE(fs::exists(dir / "out/cache/strands.0002.hpc")) << ok.output;
}

TEST(Hostile, OpenHeadIsWarnedAbout) {
    TempDir dir;
    // One triangle: three boundary edges. Scanned heads are often open at the
    // neck, so the shot runs, with a warning about the level-set collider.
    writeFile(dir / "open.obj", "v 0 0.1 0\nv 0.1 0 0\nv 0 0 0.1\nf 1 3 2\n");
    writeFile(dir / "s.yaml", shotWithHead("open.obj"));
    const ProcessResult r = runHairpipe("sim s.yaml --out out", dir.path());
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("open.obj is open (3 boundary edges)"), std::string::npos) << r.output;
    // A closed mesh (the mixed octahedron above without its extras) is not.
    writeFile(dir / "closed.obj",
              "v 0.1 0 0\nv -0.1 0 0\nv 0 0.1 0\nv 0 -0.1 0\nv 0 0 0.1\nv 0 0 -0.1\n"
              "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n");
    writeFile(dir / "c.yaml", shotWithHead("closed.obj"));
    const ProcessResult c = runHairpipe("sim c.yaml --out out2", dir.path());
    EXPECT_EQ(c.exitCode, 0) << c.output;
    EXPECT_EQ(c.output.find("boundary edges"), std::string::npos) << c.output;
    EXPECT_EQ(c.output.find("non-manifold"), std::string::npos) << c.output;
    EXPECT_EQ(c.output.find("inconsistently wound"), std::string::npos) << c.output;
    EXPECT_EQ(c.output.find("inside out"), std::string::npos) << c.output;
}

TEST(Hostile, NonManifoldAndInconsistentlyWoundHeadsAreWarnedAbout) {
    TempDir dir;
    const std::string octahedron = "v 0.1 0 0\nv -0.1 0 0\nv 0 0.1 0\nv 0 -0.1 0\nv 0 0 0.1\nv 0 0 -0.1\n";
    // A fin on edge 1-3 (a third triangle there, two new boundary edges).
    writeFile(dir / "fin.obj", octahedron + "v 0.1 0.1 0.1\n"
                               "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\nf 1 7 3\n");
    writeFile(dir / "f.yaml", shotWithHead("fin.obj"));
    const ProcessResult f = runHairpipe("sim f.yaml --out out", dir.path());
    EXPECT_EQ(f.exitCode, 0) << f.output;
    EXPECT_NE(f.output.find("fin.obj is non-manifold (1 edges shared by more than two triangles)"), std::string::npos)
        << f.output;
    EXPECT_NE(f.output.find("fin.obj is open (2 boundary edges)"), std::string::npos) << f.output;
    // One face turned over (f 3 1 5 instead of f 1 3 5): its three edges
    // each run the same way as their neighbour's.
    writeFile(dir / "flipped.obj", octahedron +
                                   "f 3 1 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n");
    writeFile(dir / "w.yaml", shotWithHead("flipped.obj"));
    const ProcessResult w = runHairpipe("sim w.yaml --out out2", dir.path());
    EXPECT_EQ(w.exitCode, 0) << w.output;
    EXPECT_NE(w.output.find("flipped.obj has inconsistently wound triangles (3 edges"), std::string::npos) << w.output;
    EXPECT_EQ(w.output.find("boundary edges"), std::string::npos) << w.output;
    // Every face turned over: consistent, closed, but inside out.
    writeFile(dir / "inverted.obj", octahedron +
                                    "f 3 1 5\nf 2 3 5\nf 4 2 5\nf 1 4 5\nf 1 3 6\nf 3 2 6\nf 2 4 6\nf 4 1 6\n");
    writeFile(dir / "i.yaml", shotWithHead("inverted.obj"));
    const ProcessResult i = runHairpipe("sim i.yaml --out out3", dir.path());
    EXPECT_NE(i.output.find("inverted.obj is inside out"), std::string::npos) << i.output;
    EXPECT_EQ(i.output.find("inconsistently wound"), std::string::npos) << i.output;
}

TEST(Hostile, ZeroLengthClip) {
    TempDir dir;
    // A glTF whose only clip has a single key at t = 0: duration 0. Looping
    // it must not divide by zero; the head holds its keyed pose.
    writeFile(dir / "still.gltf", "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0,\"name\":\"Head\"}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"buffers\":[{\"byteLength\":52,\"uri\":\"data:application/octet-stream;base64,AAAAAM3MzD0AAAAAzczMPQAAAAAAAAAAAAAAAAAAAADNzMw9AAAAAAAAAAAK1yM8AAAAAA==\"}],\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":4},{\"buffer\":0,\"byteOffset\":40,\"byteLength\":12}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[0.1,0.1,0.1]},{\"bufferView\":1,\"componentType\":5126,\"count\":1,\"type\":\"SCALAR\",\"min\":[0],\"max\":[0]},{\"bufferView\":2,\"componentType\":5126,\"count\":1,\"type\":\"VEC3\"}],\"animations\":[{\"name\":\"still\",\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}],\"samplers\":[{\"input\":1,\"output\":2,\"interpolation\":\"LINEAR\"}]}]}");
    writeFile(dir / "s.yaml", "frames: 1-3\nhead: {file: still.gltf, loop: true, scalp: {method: all}}\n"
                              "hair:\n  guides: {count: 6, segments: 4}\n  followers: {count: 10}\n");
    const ProcessResult info = runHairpipe("info s.yaml", dir.path());
    EXPECT_NE(info.output.find("0: still, 0.00 s"), std::string::npos) << info.output;
    // Whole strands in the cache (version 1), to read them back here.
    const ProcessResult r = runHairpipe("sim s.yaml --out out --set cache.followers=store", dir.path());
    EXPECT_EQ(r.exitCode, 0) << r.output;
    // readStrandCache validates (finite positions, consistent sizes).
    const hp::StrandFrame f = hp::readStrandCache(dir / "out/cache/strands.0003.hpc");
    EXPECT_EQ(f.strandCount(), 16u);
}

TEST(Hostile, ScalpSelectionThatSelectsNothing) {
    TempDir dir;
    const fs::path sphere = sourcePath("scenes/assets/sphere.glb");
    writeFile(dir / "s.yaml", "frames: 1-2\nhead:\n  file: " + sphere.string() +
                                  "\n  scalp: {method: region, center: [0, 5, 0], angle: 1}\n"
                                  "hair:\n  guides: {count: 6, segments: 4}\n");
    expectRejected(runHairpipe("sim s.yaml --out out", dir.path()),
                   {"s.yaml:4:", "'head.scalp.method': the scalp selection (region) selects no triangle"});
    writeFile(dir / "m.yaml", "frames: 1-2\nhead:\n  file: " + sphere.string() +
                                  "\n  scalp: {method: material, materials: NoSuchMaterial}\n"
                                  "hair:\n  guides: {count: 6, segments: 4}\n");
    expectRejected(runHairpipe("sim m.yaml --out out", dir.path()),
                   {"'head.scalp.materials'", "no material 'NoSuchMaterial'"});
    EXPECT_EQ(filesUnder(dir / "out"), 0u);
}

TEST(Hostile, UnwritableOutputFolder) {
    TempDir dir;
    const fs::path sphere = sourcePath("scenes/assets/sphere.glb");
    writeFile(dir / "s.yaml", shotWithHead(sphere.string()));
    writeFile(dir / "file", "not a folder");
    // Root ignores permission bits, so the folder is made impossible instead:
    // its parent is a regular file.
    const ProcessResult r = runHairpipe("sim s.yaml --out file/out", dir.path());
    expectRejected(r, {"file/out: cannot create the output folder"});
    EXPECT_EQ(readFile(dir / "file"), "not a folder");
    EXPECT_EQ(r.output.find("frame 1"), std::string::npos) << "refused before the first frame\n" << r.output;
}
