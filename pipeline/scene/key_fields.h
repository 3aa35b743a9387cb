// @brief Scene keys read into the fields of a plain settings struct, one
// table row per key: `readKeys(scene, s, {{"simulation.friction",
// &GuideSettings::friction}, ...})`. The key's schema type (number,
// integer, flag, vec3) and the field's type pick the conversion.
//
// Why a table: the *_settings.cpp mappings were runs of near-identical
// assignment lines (`s.x = float(scene.number("k"))`) repeated in every
// file; a row says only which key fills which field. Keys that need logic
// (enums from text, derived values, cross-key checks) stay as code beside
// the table.
#pragma once

#include "pipeline/scene/scene.h"

#include <cstdint>
#include <initializer_list>
#include <variant>

namespace hp {

/// One key and the field it fills. A field of a base struct (for example
/// StepSettings's time step in GuideSettings) converts to S's member pointer.
template <class S>
struct KeyField {
    using Member = std::variant<float S::*, int S::*, uint32_t S::*, bool S::*, Eigen::Vector3f S::*>;
    KeyField(const char* k, float S::*m) : key(k), member(m) {}
    KeyField(const char* k, int S::*m) : key(k), member(m) {}
    KeyField(const char* k, uint32_t S::*m) : key(k), member(m) {}
    KeyField(const char* k, bool S::*m) : key(k), member(m) {}
    KeyField(const char* k, Eigen::Vector3f S::*m) : key(k), member(m) {}
    const char* key;
    Member member;
};

namespace detail {
template <class... F>
struct Overloaded : F... {
    using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;
}  // namespace detail

/// Reads every key of `fields` from `scene` into `s`, in the table's order.
template <class S>
void readKeys(const Scene& scene, S& s, std::initializer_list<KeyField<S>> fields) {
    for (const KeyField<S>& f : fields)
        std::visit(detail::Overloaded{[&](float S::*m) { s.*m = float(scene.number(f.key)); },
                                      [&](int S::*m) { s.*m = int(scene.integer(f.key)); },
                                      [&](uint32_t S::*m) { s.*m = uint32_t(scene.integer(f.key)); },
                                      [&](bool S::*m) { s.*m = scene.flag(f.key); },
                                      [&](Eigen::Vector3f S::*m) { s.*m = scene.vec3f(f.key); }},
                   f.member);
}

}  // namespace hp
