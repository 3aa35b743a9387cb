// The scene file schema: every key with its type, default, unit, range and
// documentation. The loader (pipeline/scene/scene.h) validates against it, `--set`
// overrides go through it, and docs/scene-reference.md is generated from it
// (`hairpipe help scene`), so the reference can never drift from the code.
//
// The keys are data, pipeline/scene/keys/*.yaml (format: schema_yaml.h); a
// later stage adds its keys in its own file and lists it in schema.cpp.
#pragma once

#include <limits>
#include <string>
#include <vector>

namespace hp {

enum class KeyType {
    Bool,
    Int,
    Float,
    String,
    Enum,        ///< one of `choices`
    File,        ///< an input file, resolved against the scene's folder, must exist
    Vec3,        ///< [x, y, z]
    FrameRange,  ///< "1-120x2" grammar (pipeline/batch/frame_range.h)
    Curve,       ///< a number, or [[frame, value], ...] keys interpolated linearly
    List,        ///< a sequence of maps whose keys are registered under "path[]."
};

const char* keyTypeName(KeyType type);

struct KeySpec {
    std::string path;          ///< "hair.guides.count"; list items "render.lights[].type"
    KeyType type = KeyType::String;
    std::string defaultYaml;   ///< default as YAML text; empty = absent unless given
    std::string unit;          ///< "m", "s", "deg", "" ...
    double min = -std::numeric_limits<double>::infinity();
    double max = std::numeric_limits<double>::infinity();
    std::vector<std::string> choices;
    std::string doc;
    bool required = false;
};

struct SectionSpec {
    std::string path;
    std::string doc;
};

class Schema {
  public:
    /// The schema of hairpipe scene files (built once).
    static const Schema& scene();

    void add(KeySpec spec);
    void section(const std::string& path, const std::string& doc);
    /// Sets a key's default (YAML text); throws std::logic_error if the key is unknown.
    void setDefault(const std::string& path, std::string yaml);

    /// The key at a normalised path ("render.lights[].type"), or null.
    const KeySpec* find(const std::string& path) const;
    /// True if some key lives below `path` (it is a section).
    bool isSection(const std::string& path) const;
    /// Child names directly below a section ("" for the top level).
    std::vector<std::string> children(const std::string& section) const;
    const std::vector<KeySpec>& keys() const { return keys_; }
    const std::vector<SectionSpec>& sections() const { return sections_; }
    /// The closest known key to an unknown one, for "did you mean".
    std::string suggest(const std::string& section, const std::string& name) const;
    /// The reference page (Markdown).
    std::string markdown() const;

  private:
    std::vector<KeySpec> keys_;
    std::vector<SectionSpec> sections_;
};

/// Replaces list indices by "[]": "render.lights[2].type" -> "render.lights[].type".
std::string normalizeKeyPath(const std::string& path);

}  // namespace hp
