// A validated scene: the YAML file plus `--set` overrides, checked key by key
// against the schema (pipeline/scene/schema.h), with defaults filled in and the
// source location of every value kept for later error messages.
#pragma once

#include "core/errors.h"

#include <Eigen/Core>

#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace hp {

/// A scalar animated over frames: keys (frame, value), linear in between,
/// held constant before the first and after the last key.
struct Curve {
    std::vector<std::pair<double, double>> keys;
    double eval(double frame) const;
    bool animated() const { return keys.size() > 1; }
};

class Scene {
  public:
    /// Loads and validates `file` with overrides "key.path=value".
    /// Throws SceneError (file:line:col, key) or AssetError.
    static Scene load(const std::filesystem::path& file, const std::vector<std::string>& overrides = {});
    /// Same from text; `displayName` is used in messages, `baseDir` resolves files.
    static Scene parse(const std::string& yaml, const std::string& displayName,
                       const std::filesystem::path& baseDir, const std::vector<std::string>& overrides = {});

    bool flag(const std::string& key) const;
    long integer(const std::string& key) const;
    double number(const std::string& key) const;
    const std::string& text(const std::string& key) const;
    /// Absolute path of a File key, or empty when the key is unset/empty.
    std::filesystem::path file(const std::string& key) const;
    Eigen::Vector3d vec3(const std::string& key) const;
    Eigen::Vector3f vec3f(const std::string& key) const { return vec3(key).cast<float>(); }
    const std::vector<int>& frames(const std::string& key) const;
    const Curve& curve(const std::string& key) const;
    /// Number of items in a List key.
    size_t count(const std::string& key) const;

    /// True if the key has a value (given or default).
    bool has(const std::string& key) const;
    /// True if the user gave the key (file or --set), not a default.
    bool given(const std::string& key) const;
    /// Where a key's value came from (file:line:col, "--set", or "default").
    SourceLocation where(const std::string& key) const;
    /// Throws a SceneError at `key`'s location: for checks across keys.
    [[noreturn]] void fail(const std::string& key, const std::string& message) const;

    const std::string& name() const { return displayName_; }
    const std::filesystem::path& directory() const { return baseDir_; }
    /// The resolved scene as YAML, defaults marked (for `hairpipe info`).
    std::string dump() const;

    using Value = std::variant<bool, long, double, std::string, Eigen::Vector3d, std::vector<int>, Curve, size_t>;
    struct Entry {
        Value value;
        SourceLocation where;
        bool given = false;
    };

  private:
    const Entry& entry(const std::string& key, const char* expected) const;
    std::string displayName_;
    std::filesystem::path baseDir_;
    std::map<std::string, Entry> values_;  // concrete paths ("render.lights[0].type")
    friend class SceneLoader;
};

}  // namespace hp
