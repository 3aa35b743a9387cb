#include "pipeline/scene/scene.h"

#include "pipeline/batch/frame_range.h"
#include "pipeline/scene/scene_budget.h"
#include "pipeline/scene/schema.h"

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

namespace hp {

double Curve::eval(double frame) const {
    if (keys.empty()) return 0.0;
    if (frame <= keys.front().first) return keys.front().second;
    if (frame >= keys.back().first) return keys.back().second;
    for (size_t i = 1; i < keys.size(); ++i) {
        if (frame <= keys[i].first) {
            const auto& [f0, v0] = keys[i - 1];
            const auto& [f1, v1] = keys[i];
            return v0 + (v1 - v0) * (frame - f0) / (f1 - f0);
        }
    }
    return keys.back().second;
}

/// Walks YAML trees into a Scene's flat value map, validating as it goes.
class SceneLoader {
  public:
    SceneLoader(Scene& scene, const Schema& schema) : scene_(scene), schema_(schema) {}

    /// Where nodes of the tree being walked come from.
    struct Origin {
        std::string file;  ///< file name, or "--set ..." / "default"
        bool marks;        ///< YAML marks are meaningful (a real file)
        bool given;        ///< the user wrote it
    };

    void walkMap(const YAML::Node& map, const std::string& prefix, const Origin& origin) {
        std::set<std::string> seen;
        for (const auto& kv : map) {
            const std::string name = kv.first.Scalar();
            const std::string path = prefix.empty() ? name : prefix + "." + name;
            if (!seen.insert(name).second) fail(kv.first, origin, path, "duplicate key");
            walkKey(path, kv.first, kv.second, origin);
        }
    }

    void walkKey(const std::string& path, const YAML::Node& keyNode, const YAML::Node& value, const Origin& origin) {
        const std::string norm = normalizeKeyPath(path);
        if (const KeySpec* spec = schema_.find(norm)) {
            if (spec->type == KeyType::List) walkList(path, *spec, value, origin);
            else setLeaf(path, *spec, value, origin);
            return;
        }
        if (schema_.isSection(norm)) {
            if (value.IsNull()) return;  // "hair:" with nothing under it
            if (!value.IsMap()) fail(value, origin, path, "is a section: expected a map of keys");
            walkMap(value, path, origin);
            return;
        }
        const size_t dot = norm.rfind('.');
        const std::string section = dot == std::string::npos ? "" : norm.substr(0, dot);
        const std::string leaf = dot == std::string::npos ? norm : norm.substr(dot + 1);
        const std::string hint = schema_.suggest(section, leaf);
        fail(keyNode, origin, path,
             "unknown key" + (hint.empty() ? std::string() : " (did you mean '" + hint + "'?)"));
    }

    void walkList(const std::string& path, const KeySpec& spec, const YAML::Node& value, const Origin& origin) {
        if (!value.IsSequence()) fail(value, origin, path, "expected a list");
        if (double(value.size()) > spec.max)
            fail(value, origin, path, cat("has ", value.size(), " items; at most ", spec.max, " allowed"));
        // Replace any previous list (a --set of the whole list).
        const std::string prefix = path + "[";
        for (auto it = scene_.values_.lower_bound(prefix);
             it != scene_.values_.end() && it->first.compare(0, prefix.size(), prefix) == 0;)
            it = scene_.values_.erase(it);
        for (size_t i = 0; i < value.size(); ++i) {
            const YAML::Node item = value[i];
            const std::string itemPath = cat(path, "[", i, "]");
            if (!item.IsMap()) fail(item, origin, itemPath, "expected a map");
            walkMap(item, itemPath, origin);
        }
        scene_.values_[path] = {value.size(), locate(value, origin), origin.given};
    }

    void setLeaf(const std::string& path, const KeySpec& spec, const YAML::Node& v, const Origin& origin) {
        scene_.values_[path] = {convert(path, spec, v, origin), locate(v, origin), origin.given};
    }

    /// Applies one "key.path=value" override.
    void applyOverride(const std::string& text) {
        const size_t eq = text.find('=');
        const Origin origin{"--set " + text, false, true};
        const std::string key = eq == std::string::npos ? text : text.substr(0, eq);
        if (eq == std::string::npos || key.empty())
            throw SceneError({origin.file}, key, "expected key.path=value");
        YAML::Node value;
        try {
            value = YAML::Load(text.substr(eq + 1));
        } catch (const YAML::Exception& e) {
            throw SceneError({origin.file}, key, "value is not valid YAML: " + e.msg);
        }
        const std::string norm = normalizeKeyPath(key);
        // "key=" with nothing after it: YAML reads that as null ("has no
        // value"), but on a command line it means the empty string, which a
        // text key takes (--set reference.png= writes no PNG). Keys of other
        // types still report that they have no value.
        if (const KeySpec* spec = schema_.find(norm);
            spec && (spec->type == KeyType::String || spec->type == KeyType::File) &&
            text.find_first_not_of(" \t", eq + 1) == std::string::npos)
            value = YAML::Node(std::string());
        if (!schema_.find(norm) && schema_.isSection(norm)) {
            if (!value.IsMap()) throw SceneError({origin.file}, key, "is a section: set one of its keys");
            walkMap(value, key, origin);
            return;
        }
        // A key inside a list item needs that item to exist.
        const size_t bracket = key.rfind('[');
        if (bracket != std::string::npos) {
            const std::string list = key.substr(0, bracket);
            const size_t index = std::strtoul(key.c_str() + bracket + 1, nullptr, 10);
            if (index >= countOf(list))
                throw SceneError({origin.file}, key, cat("the list '", list, "' has only ", countOf(list), " items"));
        }
        walkKey(key, YAML::Node(), value, origin);
    }

    /// Default lists for absent list keys (before overrides, which may index them).
    void fillListDefaults() {
        const Origin origin{"default", false, false};
        for (const KeySpec& spec : schema_.keys())
            if (spec.type == KeyType::List && !spec.defaultYaml.empty() && !scene_.values_.count(spec.path))
                walkList(spec.path, spec, YAML::Load(spec.defaultYaml), origin);
    }

    /// Defaults for absent keys, including the keys of every list item.
    void fillDefaults() {
        const Origin origin{"default", false, false};
        for (const KeySpec& spec : schema_.keys()) {
            if (spec.type == KeyType::List) continue;
            const size_t item = spec.path.find("[].");
            if (item == std::string::npos) {
                fillDefault(spec.path, spec, origin);
                continue;
            }
            const std::string list = spec.path.substr(0, item);
            for (size_t i = 0; i < countOf(list); ++i)
                fillDefault(cat(list, "[", i, "]", spec.path.substr(item + 2)), spec, origin);
        }
    }

  private:
    size_t countOf(const std::string& list) const {
        auto it = scene_.values_.find(list);
        return it == scene_.values_.end() ? 0 : std::get<size_t>(it->second.value);
    }

    void fillDefault(const std::string& path, const KeySpec& spec, const Origin& origin) {
        if (scene_.values_.count(path)) return;
        if (spec.required)
            throw SceneError({scene_.displayName_}, path, "required key is missing");
        if (spec.defaultYaml.empty()) return;
        setLeaf(path, spec, YAML::Load(spec.defaultYaml), origin);
    }

    SourceLocation locate(const YAML::Node& node, const Origin& origin) const {
        if (!origin.marks || !node.IsDefined()) return {origin.file};
        const YAML::Mark m = node.Mark();
        return {origin.file, m.line + 1, m.column + 1};
    }

    [[noreturn]] void fail(const YAML::Node& node, const Origin& origin, const std::string& path,
                           const std::string& message) const {
        throw SceneError(locate(node, origin), path, message);
    }

    /// YAML 1.2's spellings of infinity and not-a-number (.inf, -.Inf, .NAN...),
    /// which strtod does not read: reported as non-finite, not as "not a number".
    static bool isYamlNonFinite(const std::string& s) {
        std::string t = s;
        if (!t.empty() && (t[0] == '+' || t[0] == '-')) t.erase(0, 1);
        return t == ".inf" || t == ".Inf" || t == ".INF" || t == ".nan" || t == ".NaN" || t == ".NAN";
    }

    static std::string show(const YAML::Node& v) {
        if (v.IsScalar()) return "'" + v.Scalar() + "'";
        if (v.IsSequence()) return "a list";
        if (v.IsMap()) return "a map";
        return "nothing";
    }

    double number(const std::string& path, const KeySpec& spec, const YAML::Node& v, const Origin& o,
                  const char* what) const {
        if (!v.IsScalar()) fail(v, o, path, cat("expected ", what, ", got ", show(v)));
        const std::string& s = v.Scalar();
        char* end = nullptr;
        errno = 0;
        const double x = std::strtod(s.c_str(), &end);
        if (isYamlNonFinite(s)) fail(v, o, path, cat("must be a finite number, got ", show(v)));
        if (s.empty() || end != s.c_str() + s.size()) fail(v, o, path, cat("expected ", what, ", got ", show(v)));
        if (!std::isfinite(x) || errno == ERANGE) fail(v, o, path, cat("must be a finite number, got ", show(v)));
        if (x < spec.min || x > spec.max)
            fail(v, o, path, cat("must be in [", spec.min, ", ", spec.max, "]", spec.unit.empty() ? "" : " ",
                                 spec.unit, ", got ", s));
        return x;
    }

    Scene::Value convert(const std::string& path, const KeySpec& spec, const YAML::Node& v, const Origin& o) {
        if (!v.IsDefined() || v.IsNull()) fail(v, o, path, "has no value");
        switch (spec.type) {
        case KeyType::Bool: {
            static const std::set<std::string> yes{"true", "True", "TRUE", "yes", "on"},
                no{"false", "False", "FALSE", "no", "off"};
            if (v.IsScalar() && yes.count(v.Scalar())) return true;
            if (v.IsScalar() && no.count(v.Scalar())) return false;
            fail(v, o, path, "expected true or false, got " + show(v));
        }
        case KeyType::Int: {
            if (!v.IsScalar()) fail(v, o, path, "expected an integer, got " + show(v));
            const std::string& s = v.Scalar();
            char* end = nullptr;
            errno = 0;
            const long x = std::strtol(s.c_str(), &end, 10);
            if (s.empty() || end != s.c_str() + s.size()) fail(v, o, path, "expected an integer, got " + show(v));
            if (errno == ERANGE || double(x) < spec.min || double(x) > spec.max)
                fail(v, o, path, cat("must be in [", long(spec.min), ", ", long(spec.max), "]",
                                     spec.unit.empty() ? "" : " ", spec.unit, ", got ", s));
            return x;
        }
        case KeyType::Float: return number(path, spec, v, o, "a number");
        case KeyType::String:
            if (!v.IsScalar()) fail(v, o, path, "expected a string, got " + show(v));
            return v.Scalar();
        case KeyType::Enum: {
            if (v.IsScalar())
                for (const std::string& c : spec.choices)
                    if (c == v.Scalar()) return c;
            std::string list;
            for (const std::string& c : spec.choices) list += (list.empty() ? "" : ", ") + c;
            fail(v, o, path, "expected one of " + list + ", got " + show(v));
        }
        case KeyType::File: {
            if (!v.IsScalar()) fail(v, o, path, "expected a file path, got " + show(v));
            if (v.Scalar().empty()) {
                if (spec.required) fail(v, o, path, "needs a file");
                return std::string();
            }
            std::filesystem::path p(v.Scalar());
            // Paths in the file are relative to the scene's folder; on the
            // command line (--set) they are relative to where the user is.
            if (p.is_relative()) p = o.marks || !o.given ? scene_.baseDir_ / p : std::filesystem::absolute(p);
            p = p.lexically_normal();
            std::error_code ec;
            if (!std::filesystem::is_regular_file(p, ec)) fail(v, o, path, "file not found: " + p.string());
            return p.string();
        }
        case KeyType::Vec3: {
            if (!v.IsSequence() || v.size() != 3) fail(v, o, path, "expected [x, y, z], got " + show(v));
            Eigen::Vector3d x;
            for (int i = 0; i < 3; ++i) x[i] = number(path, spec, v[i], o, "a number");
            return x;
        }
        case KeyType::FrameRange: {
            if (!v.IsScalar()) fail(v, o, path, "expected a frame range like 1-120, got " + show(v));
            try {
                return parseFrameRange(v.Scalar());
            } catch (const UsageError& e) {
                fail(v, o, path, e.what());
            }
        }
        case KeyType::Curve: {
            Curve c;
            if (v.IsScalar()) {
                c.keys.emplace_back(0.0, number(path, spec, v, o, "a number or [[frame, value], ...]"));
                return c;
            }
            if (!v.IsSequence() || v.size() == 0)
                fail(v, o, path, "expected a number or a list of [frame, value] keys, got " + show(v));
            const KeySpec frameSpec{};
            for (size_t i = 0; i < v.size(); ++i) {
                const YAML::Node k = v[i];
                if (!k.IsSequence() || k.size() != 2) fail(k, o, path, "each key must be [frame, value]");
                const double frame = number(path, frameSpec, k[0], o, "a frame number");
                const double value = number(path, spec, k[1], o, "a number");
                if (!c.keys.empty() && frame <= c.keys.back().first)
                    fail(k, o, path, "key frames must increase");
                c.keys.emplace_back(frame, value);
            }
            return c;
        }
        case KeyType::List: break;
        }
        fail(v, o, path, "internal: unexpected key type");
    }

    Scene& scene_;
    const Schema& schema_;
};

namespace {

constexpr uintmax_t kMaxSceneFileBytes = 16u << 20;

/// True if some line holds more than blanks or a comment.
bool hasContent(const std::string& text) {
    std::istringstream lines(text);
    std::string line;
    while (std::getline(lines, line)) {
        const size_t first = line.find_first_not_of(" \t\r");
        if (first != std::string::npos && line[first] != '#') return true;
    }
    return false;
}

}  // namespace

Scene Scene::parse(const std::string& yaml, const std::string& displayName, const std::filesystem::path& baseDir,
                   const std::vector<std::string>& overrides) {
    Scene scene;
    scene.displayName_ = displayName;
    scene.baseDir_ = baseDir;
    YAML::Node root;
    try {
        root = YAML::Load(yaml);
    } catch (const YAML::DeepRecursion& e) {
        // yaml-cpp's recursive parser stops at 2000 levels instead of
        // overflowing the stack; say so instead of its generic "bad file".
        throw SceneError({displayName, e.mark.line + 1, e.mark.column + 1}, "",
                         "YAML nested too deeply (a scene needs a handful of levels)");
    } catch (const YAML::ParserException& e) {
        throw SceneError({displayName, e.mark.line + 1, e.mark.column + 1}, "", "YAML syntax error: " + e.msg);
    } catch (const YAML::Exception& e) {
        throw SceneError({displayName}, "", std::string("cannot parse YAML: ") + e.what());
    }
    SceneLoader loader(scene, Schema::scene());
    if (root.IsDefined() && !root.IsNull()) {
        if (!root.IsMap()) {
            const YAML::Mark m = root.Mark();
            throw SceneError({displayName, m.line + 1, m.column + 1}, "", "a scene must be a map of keys");
        }
        loader.walkMap(root, "", {displayName, true, true});
    }
    loader.fillListDefaults();
    for (const std::string& o : overrides) loader.applyOverride(o);
    loader.fillDefaults();
    checkSceneBudget(scene);  // before any stage allocates for the scene
    return scene;
}

Scene Scene::load(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) throw AssetError(file.string(), "scene file not found");
    // A scene is a few kilobytes; a huge file is the wrong file (a cache, an
    // image), refused before reading it into memory and parsing it.
    const uintmax_t size = std::filesystem::file_size(file, ec);
    if (ec) throw AssetError(file.string(), "cannot read scene file: " + ec.message());
    if (size > kMaxSceneFileBytes)
        throw AssetError(file.string(), cat("scene file is ", size, " bytes; scenes over ", kMaxSceneFileBytes,
                                            " bytes are refused (is this the right file?)"));
    std::ifstream in(file, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    if (!in.good() && !in.eof()) throw AssetError(file.string(), "cannot read scene file");
    const std::string& t = text.str();
    if (const size_t nul = t.find('\0'); nul != std::string::npos)
        throw AssetError(file.string(), cat("is not a text file (a NUL byte at offset ", nul, ")"));
    if (!hasContent(t)) throw AssetError(file.string(), "scene file is empty (no keys, only blanks or comments)");
    const std::filesystem::path dir = std::filesystem::absolute(file).parent_path();
    return parse(t, file.string(), dir, overrides);
}

const Scene::Entry& Scene::entry(const std::string& key, const char* expected) const {
    auto it = values_.find(key);
    if (it == values_.end()) {
        if (!Schema::scene().find(normalizeKeyPath(key)))
            throw std::logic_error("scene key not in the schema: " + key);
        throw SceneError({displayName_}, key, cat("has no value (", expected, " expected)"));
    }
    return it->second;
}

bool Scene::flag(const std::string& key) const { return std::get<bool>(entry(key, "bool").value); }
long Scene::integer(const std::string& key) const { return std::get<long>(entry(key, "integer").value); }
double Scene::number(const std::string& key) const { return std::get<double>(entry(key, "number").value); }
const std::string& Scene::text(const std::string& key) const {
    return std::get<std::string>(entry(key, "string").value);
}
std::filesystem::path Scene::file(const std::string& key) const {
    if (!has(key)) return {};
    return std::get<std::string>(entry(key, "file").value);
}
Eigen::Vector3d Scene::vec3(const std::string& key) const {
    return std::get<Eigen::Vector3d>(entry(key, "vec3").value);
}
const std::vector<int>& Scene::frames(const std::string& key) const {
    return std::get<std::vector<int>>(entry(key, "frame range").value);
}
const Curve& Scene::curve(const std::string& key) const { return std::get<Curve>(entry(key, "curve").value); }
size_t Scene::count(const std::string& key) const {
    return has(key) ? std::get<size_t>(values_.at(key).value) : 0;
}
bool Scene::has(const std::string& key) const { return values_.count(key) > 0; }
bool Scene::given(const std::string& key) const {
    auto it = values_.find(key);
    return it != values_.end() && it->second.given;
}
SourceLocation Scene::where(const std::string& key) const {
    auto it = values_.find(key);
    return it == values_.end() ? SourceLocation{displayName_} : it->second.where;
}
void Scene::fail(const std::string& key, const std::string& message) const {
    throw SceneError(where(key), key, message);
}

namespace {
struct Printer {
    std::ostream& out;
    void operator()(bool b) { out << (b ? "true" : "false"); }
    void operator()(long x) { out << x; }
    void operator()(double x) { out << x; }
    void operator()(const std::string& s) { out << '"' << s << '"'; }
    void operator()(const Eigen::Vector3d& v) { out << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]"; }
    void operator()(const std::vector<int>& f) { out << '"' << formatFrameRange(f) << '"'; }
    void operator()(const Curve& c) {
        if (c.keys.size() == 1) {
            out << c.keys[0].second;
            return;
        }
        out << "[";
        for (size_t i = 0; i < c.keys.size(); ++i)
            out << (i ? ", " : "") << "[" << c.keys[i].first << ", " << c.keys[i].second << "]";
        out << "]";
    }
    void operator()(size_t n) { out << "(" << n << " items)"; }
};
}  // namespace

std::string Scene::dump() const {
    std::ostringstream out;
    for (const auto& [key, e] : values_) {
        out << key << ": ";
        std::visit(Printer{out}, e.value);
        out << (e.given ? "" : "    # default") << "\n";
    }
    return out.str();
}

}  // namespace hp
