// The scene schema as data: pipeline/scene/keys/*.yaml, one file per group of
// sections, each a list of entries
//
//   - section: hair.curly          # a section of the reference page
//     doc: ...
//   - key: hair.curly.particles    # a key: path, type, default, range, unit, doc
//     type: integer
//     default: 24
//     range: [2, 1000]
//     doc: Particles per guide.
//
// Fields of a key: `type` (one of keyTypeName's names: bool, integer, number,
// string, choice, file, vec3, frame range, curve, list), `doc` (both
// required); `default`, `range: [min, max]` (.inf allowed), `unit`,
// `choices: [...]` (choice), `max_items` (list), `required: true`. A list's
// default is YAML text ("[{}]"). The files are compiled into the library
// (cmake/EmbedFiles.cmake), so the binary needs no source tree, and
// docs/scene-reference.md is generated from them.
//
// Why data rather than code: the declarations were hundreds of lines of one
// call shape; as data they read as the table they are, and a key is added by
// writing its entry, not code.
#pragma once

#include "pipeline/scene/schema.h"

#include <string>
#include <vector>

namespace hp {

/// One schema file: its name (e.g. "curly.yaml") and text.
struct SchemaFile {
    const char* name;
    const char* text;
};

/// pipeline/scene/keys/*.yaml as compiled into the library (sorted by name).
const std::vector<SchemaFile>& embeddedSceneKeyFiles();

/// @brief Adds the sections and keys of one schema file to `schema`, in file order.
/// @param schema  receives the entries (a section opened twice keeps its first doc)
/// @param file    the file's name (for messages) and YAML text
/// @throws SceneError naming "keys/<file>:line:column" and the key for a malformed entry,
///         an unknown field or type, a default that does not parse or a key given twice.
void readSchemaFile(Schema& schema, const SchemaFile& file);

}  // namespace hp
