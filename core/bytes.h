// @brief Byte buffers for the project's binary files: the strand cache, the
// settled groom and the solvers' checkpoints. Plain values and arrays are
// appended in order and read back in the same order; a reader never reads
// past its data and reports why through the caller's own error (each file
// type names itself and its file).
//
// Why one pair: the three formats were written with three hand-rolled copies
// of the same append/copy loops, and one had lost the empty-array guard the
// others needed (memcpy from a null data() is undefined even for 0 bytes).
#pragma once

#include <cstdint>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace hp {

/// Appends values in memory order (little-endian on every target we build).
class ByteWriter {
  public:
    template <typename T>
    void put(const T& value) { bytes(&value, sizeof(T)); }
    /// The elements of `v` without a count (the format stores the count).
    template <typename T>
    void values(const std::vector<T>& v) { bytes(v.data(), v.size() * sizeof(T)); }
    /// A u64 element count, then the elements.
    template <typename T>
    void sized(const std::vector<T>& v) {
        put(uint64_t(v.size()));
        values(v);
    }
    void bytes(const void* p, size_t n) {
        if (n == 0) return;
        // resize + memcpy rather than insert: GCC 12 warns (falsely) about
        // insert's inlined copy into a freshly grown vector.
        const size_t at = data.size();
        data.resize(at + n);
        std::memcpy(data.data() + at, p, n);
    }
    std::vector<char> data;
};

/// Reads values back in order. `fail` is called with a short reason
/// ("truncated", ...) and must throw; the reader never returns past it.
class ByteReader {
  public:
    using Fail = std::function<void(const std::string& why)>;
    ByteReader(const std::vector<char>& data, Fail fail) : data_(data), fail_(std::move(fail)) {}

    template <typename T>
    T get() {
        T value;
        bytes(&value, sizeof(T));
        return value;
    }
    /// `count` elements; the count is checked against what is left before
    /// anything is allocated, so a corrupt count cannot ask for terabytes.
    template <typename T>
    void values(std::vector<T>& v, uint64_t count) {
        if (count > remaining() / sizeof(T)) fail("truncated (arrays extend past the end of the data)");
        v.resize(size_t(count));
        bytes(v.data(), size_t(count) * sizeof(T));
    }
    void bytes(void* out, size_t n) {
        if (n > remaining()) fail("truncated");
        if (n == 0) return;  // an empty array's data() may be null: memcpy(nullptr, ..., 0) is UB
        std::memcpy(out, data_.data() + pos_, n);
        pos_ += n;
    }
    size_t remaining() const { return data_.size() - pos_; }
    [[noreturn]] void fail(const std::string& why) const {
        fail_(why);
        throw std::logic_error("ByteReader: the fail callback returned");
    }

  private:
    const std::vector<char>& data_;
    Fail fail_;
    size_t pos_ = 0;
};

}  // namespace hp
