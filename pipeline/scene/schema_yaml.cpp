#include "pipeline/scene/schema_yaml.h"

#include "core/errors.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <set>

namespace hp {
namespace {

/// Reads one file's entries; every failure names the file, the entry's line and its key.
class SchemaFileReader {
  public:
    SchemaFileReader(Schema& schema, const SchemaFile& file) : schema_(schema), name_(file.name) {
        try {
            root_ = YAML::Load(file.text);
        } catch (const YAML::Exception& e) {
            throw SceneError({"keys/" + name_, e.mark.line + 1, e.mark.column + 1}, "", e.msg);
        }
    }

    void read() {
        if (!root_.IsSequence()) fail(root_, "", "expected a list of `section:` and `key:` entries");
        for (const YAML::Node& entry : root_) {
            if (!entry.IsMap()) fail(entry, "", "expected a map with `section:` or `key:`");
            if (entry["section"]) readSection(entry);
            else if (entry["key"]) readKey(entry);
            else fail(entry, "", "an entry needs `section:` or `key:`");
        }
    }

  private:
    [[noreturn]] void fail(const YAML::Node& at, const std::string& key, const std::string& message) const {
        const YAML::Mark m = at.Mark();
        throw SceneError({"keys/" + name_, m.line + 1, m.column + 1}, key, message);
    }

    std::string text(const YAML::Node& entry, const char* field, const std::string& key) const {
        const YAML::Node v = entry[field];
        if (!v) return "";
        if (!v.IsScalar()) fail(v, key, cat("`", field, "` must be text"));
        return v.Scalar();
    }

    double number(const YAML::Node& v, const std::string& key, const char* field) const {
        try {
            return v.as<double>();  // yaml-cpp reads .inf / -.inf as well
        } catch (const YAML::Exception&) {
            fail(v, key, cat("`", field, "` must be a number, got '", v.IsScalar() ? v.Scalar() : "?", "'"));
        }
    }

    /// Rejects fields that no entry of this kind has (a typo would silently drop a default).
    void onlyFields(const YAML::Node& entry, const std::string& key, const std::set<std::string>& allowed) const {
        for (const auto& kv : entry) {
            const std::string field = kv.first.as<std::string>();
            if (!allowed.count(field)) fail(kv.first, key, "unknown field `" + field + "`");
        }
    }

    void readSection(const YAML::Node& entry) {
        onlyFields(entry, "", {"section", "doc"});
        const std::string path = text(entry, "section", "");
        if (!entry["doc"]) fail(entry, path, "a section needs `doc`");
        schema_.section(path, text(entry, "doc", path));
    }

    static std::optional<KeyType> typeNamed(const std::string& name) {
        for (KeyType t : {KeyType::Bool, KeyType::Int, KeyType::Float, KeyType::String, KeyType::Enum, KeyType::File,
                          KeyType::Vec3, KeyType::FrameRange, KeyType::Curve, KeyType::List})
            if (name == keyTypeName(t)) return t;
        return std::nullopt;
    }

    bool flag(const YAML::Node& v, const std::string& key, const char* field) const {
        try {
            return v.as<bool>();
        } catch (const YAML::Exception&) {
            fail(v, key, cat("`", field, "` is true or false"));
        }
    }

    /// The builder's number format for defaults: what `hairpipe help scene` shows.
    static std::string yamlNumber(double v) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.10g", v);
        return buf;
    }

    /// The default as YAML text, normalised per type (numbers as %.10g, strings quoted).
    std::string defaultYaml(const YAML::Node& entry, const KeySpec& k) const {
        const YAML::Node v = entry["default"];
        if (!v) return k.type == KeyType::String ? "\"\"" : "";
        if (k.type == KeyType::Vec3) {
            if (!v.IsSequence() || v.size() != 3) fail(v, k.path, "a vec3 default is [x, y, z]");
            return "[" + yamlNumber(number(v[0], k.path, "default")) + ", " +
                   yamlNumber(number(v[1], k.path, "default")) + ", " + yamlNumber(number(v[2], k.path, "default")) +
                   "]";
        }
        if (!v.IsScalar()) fail(v, k.path, "`default` must be a scalar (a list's default is YAML text)");
        switch (k.type) {
        case KeyType::Bool: return flag(v, k.path, "default") ? "true" : "false";
        case KeyType::Int: {
            const double x = number(v, k.path, "default");
            if (x != std::floor(x)) fail(v, k.path, "an integer default must be whole");
            return std::to_string(long(x));
        }
        case KeyType::Float:
        case KeyType::Curve: return yamlNumber(number(v, k.path, "default"));
        case KeyType::String: return "\"" + v.Scalar() + "\"";
        default: return v.Scalar();
        }
    }

    void readKey(const YAML::Node& entry) {
        KeySpec k;
        k.path = text(entry, "key", "");
        onlyFields(entry, k.path, {"key", "type", "default", "range", "unit", "choices", "max_items", "required", "doc"});
        const std::optional<KeyType> type = typeNamed(text(entry, "type", k.path));
        if (!type) fail(entry["type"] ? entry["type"] : entry, k.path, "`type` must be one of keyTypeName's names");
        k.type = *type;
        if (!entry["doc"]) fail(entry, k.path, "a key needs `doc`");
        k.doc = text(entry, "doc", k.path);
        k.unit = text(entry, "unit", k.path);
        if (const YAML::Node r = entry["range"]) {
            if (!r.IsSequence() || r.size() != 2) fail(r, k.path, "`range` is [min, max]");
            k.min = number(r[0], k.path, "range");
            k.max = number(r[1], k.path, "range");
        }
        if (k.type == KeyType::List) {
            if (!entry["max_items"]) fail(entry, k.path, "a list needs `max_items`");
            k.min = 0;
            k.max = number(entry["max_items"], k.path, "max_items");
        }
        if (const YAML::Node c = entry["choices"]) {
            if (!c.IsSequence()) fail(c, k.path, "`choices` is a list");
            for (const YAML::Node& choice : c) k.choices.push_back(choice.Scalar());
        }
        if (k.type == KeyType::Enum && k.choices.empty()) fail(entry, k.path, "a choice needs `choices`");
        k.required = entry["required"] && flag(entry["required"], k.path, "required");
        k.defaultYaml = defaultYaml(entry, k);
        if (schema_.find(k.path)) fail(entry, k.path, "key given twice");
        schema_.add(std::move(k));
    }

    Schema& schema_;
    std::string name_;
    YAML::Node root_;
};

}  // namespace

void readSchemaFile(Schema& schema, const SchemaFile& file) { SchemaFileReader(schema, file).read(); }

}  // namespace hp
