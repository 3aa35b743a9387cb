#include "pipeline/scene/schema.h"

#include "core/errors.h"
#include "pipeline/scene/schema_yaml.h"
#include "render/view/view.h"

#include <algorithm>
#include <iterator>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

namespace hp {

const char* keyTypeName(KeyType type) {
    switch (type) {
    case KeyType::Bool: return "bool";
    case KeyType::Int: return "integer";
    case KeyType::Float: return "number";
    case KeyType::String: return "string";
    case KeyType::Enum: return "choice";
    case KeyType::File: return "file";
    case KeyType::Vec3: return "vec3";
    case KeyType::FrameRange: return "frame range";
    case KeyType::Curve: return "curve";
    case KeyType::List: return "list";
    }
    return "?";
}

namespace {

/// The schema files in the order of docs/scene-reference.md's sections.
const char* const kSceneKeyFileOrder[] = {"shot.yaml",      "head.yaml",    "hair.yaml",    "followers.yaml",
                                          "simulation.yaml", "curly.yaml",   "cache.yaml",   "render.yaml",
                                          "preview.yaml",   "reference.yaml", "vdb.yaml",   "compare.yaml",
                                          "budget.yaml"};

/// render.lights' default: render/view/view.cpp's threePointRig() as a YAML list,
/// so the rig is written down once (keys/render.yaml leaves it out).
std::string lightRigYaml() {
    std::ostringstream out;
    auto vec = [&](const Vec3f& v) { out << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]"; };
    out << "[";
    const std::vector<Light> rig = threePointRig();
    for (size_t i = 0; i < rig.size(); ++i) {
        const Light& l = rig[i];
        out << (i ? ", " : "") << "{type: directional, space: camera, direction: ";
        vec(l.direction);
        out << ", color: ";
        vec(l.color);
        out << ", intensity: " << l.intensity << (l.castsShadows ? "" : ", shadows: false") << "}";
    }
    out << "]";
    return out.str();
}

}  // namespace

const Schema& Schema::scene() {
    static const Schema schema = [] {
        const std::vector<SchemaFile>& files = embeddedSceneKeyFiles();
        // Every compiled-in file is read, in the listed order; an unlisted one is a build mistake.
        if (files.size() != std::size(kSceneKeyFileOrder))
            throw std::logic_error("pipeline/scene/keys/ and schema.cpp's kSceneKeyFileOrder list different files");
        Schema s;
        for (const char* name : kSceneKeyFileOrder) {
            auto it = std::find_if(files.begin(), files.end(),
                                   [&](const SchemaFile& f) { return std::string(f.name) == name; });
            if (it == files.end()) throw std::logic_error(std::string("scene key file missing: keys/") + name);
            readSchemaFile(s, *it);
        }
        s.setDefault("render.lights", lightRigYaml());
        return s;
    }();
    return schema;
}

void Schema::add(KeySpec spec) {
    if (find(spec.path)) throw std::logic_error("schema key registered twice: " + spec.path);
    keys_.push_back(std::move(spec));
}

void Schema::setDefault(const std::string& path, std::string yaml) {
    for (KeySpec& k : keys_)
        if (k.path == path) return void(k.defaultYaml = std::move(yaml));
    throw std::logic_error("schema has no key " + path);
}

void Schema::section(const std::string& path, const std::string& doc) {
    // Several files may open the same section (e.g. "hair"); the first doc wins.
    for (const SectionSpec& s : sections_)
        if (s.path == path) return;
    sections_.push_back({path, doc});
}

const KeySpec* Schema::find(const std::string& path) const {
    for (const KeySpec& k : keys_)
        if (k.path == path) return &k;
    return nullptr;
}

bool Schema::isSection(const std::string& path) const {
    const std::string prefix = path + ".";
    for (const KeySpec& k : keys_)
        if (k.path.compare(0, prefix.size(), prefix) == 0) return true;
    return false;
}

std::vector<std::string> Schema::children(const std::string& section) const {
    std::set<std::string> names;
    const std::string prefix = section.empty() ? "" : section + ".";
    for (const KeySpec& k : keys_) {
        if (k.path.compare(0, prefix.size(), prefix) != 0) continue;
        std::string rest = k.path.substr(prefix.size());
        const size_t cut = rest.find_first_of(".[");
        names.insert(rest.substr(0, cut));
    }
    return {names.begin(), names.end()};
}

namespace {

size_t editDistance(const std::string& a, const std::string& b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diag = row[0];
        row[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            const size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diag = up;
        }
    }
    return row[b.size()];
}

}  // namespace

std::string Schema::suggest(const std::string& section, const std::string& name) const {
    std::string best;
    size_t bestDistance = std::max<size_t>(2, name.size() / 3) + 1;
    for (const std::string& candidate : children(section)) {
        const size_t d = editDistance(name, candidate);
        if (d < bestDistance) bestDistance = d, best = candidate;
    }
    return best;
}

std::string normalizeKeyPath(const std::string& path) {
    std::string out;
    for (size_t i = 0; i < path.size(); ++i) {
        out += path[i];
        if (path[i] == '[') {
            while (i + 1 < path.size() && path[i + 1] != ']') ++i;
        }
    }
    return out;
}

namespace {

std::string formatNumber(double v) {
    if (std::isinf(v)) return v > 0 ? "∞" : "-∞";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

std::string rangeText(const KeySpec& k) {
    const bool lo = std::isfinite(k.min), hi = std::isfinite(k.max);
    if (k.type == KeyType::Enum) {
        std::string s;
        for (const std::string& c : k.choices) s += (s.empty() ? "" : ", ") + ("`" + c + "`");
        return s;
    }
    if (!lo && !hi) return "";
    return "[" + (lo ? formatNumber(k.min) : "-∞") + ", " + (hi ? formatNumber(k.max) : "∞") + "]" +
           (k.type == KeyType::List ? " items" : "");
}

std::string escapePipes(std::string s) {
    for (size_t i = 0; (i = s.find('|', i)) != std::string::npos; i += 2) s.replace(i, 1, "\\|");
    return s;
}

}  // namespace

std::string Schema::markdown() const {
    std::ostringstream out;
    out << "# Scene file reference\n\n"
           "<!-- Generated by `hairpipe help scene`; edit pipeline/scene/keys/*.yaml, not this file. -->\n\n"
           "A scene is a YAML file. Every key below is optional unless marked required; absent keys take\n"
           "their default. Unknown keys, wrong types and out-of-range values are errors that name the\n"
           "file, line, column and key. Any key can be overridden from the command line with\n"
           "`--set key.path=value` (list items: `--set render.lights[0].intensity=5`); the value is\n"
           "parsed as YAML and validated like the file. Relative file paths are resolved against the\n"
           "scene file's folder. Units: metres, seconds, degrees; right-handed, Y up.\n\n"
           "Types: `curve` is a number or a list of `[frame, value]` keys, linearly interpolated and held\n"
           "constant outside the keys; `frame range` uses the grammar `5`, `1-120`, `1-120x2`, `3,7,10-20`;\n"
           "`vec3` is `[x, y, z]`.\n";
    for (const SectionSpec& sec : sections_) {
        out << "\n## `" << sec.path << "`\n\n" << sec.doc << "\n\n";
        out << "| key | type | default | unit | range / choices | description |\n";
        out << "|---|---|---|---|---|---|\n";
        for (const KeySpec& k : keys_) {
            // A key belongs to the most specific section that prefixes it.
            const SectionSpec* owner = nullptr;
            for (const SectionSpec& s : sections_) {
                const std::string prefix = s.path.empty() ? "" : s.path + ".";
                const std::string listPrefix = s.path + "[].";
                const bool inside = (s.path.empty() && k.path.find_first_of(".[") == std::string::npos) ||
                                    (!s.path.empty() && (k.path.compare(0, prefix.size(), prefix) == 0 ||
                                                         k.path.compare(0, listPrefix.size(), listPrefix) == 0));
                if (inside && (!owner || s.path.size() > owner->path.size())) owner = &s;
            }
            if (owner != &sec) continue;
            out << "| `" << k.path << "` | " << keyTypeName(k.type) << " | "
                << (k.defaultYaml.empty() ? (k.required ? "**required**" : "—") : "`" + escapePipes(k.defaultYaml) + "`")
                << " | " << k.unit << " | " << escapePipes(rangeText(k)) << " | " << escapePipes(k.doc) << " |\n";
        }
    }
    return out.str();
}

}  // namespace hp
