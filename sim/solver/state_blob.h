// Byte blobs of plain values and arrays, appended and read back in the same
// order with sizes checked, so what is read holds exactly the bits written:
// solver checkpoints (arrays carry their size) and the strand cache
// (pipeline/batch/strand_cache.cpp: raw arrays whose sizes its header gives).
#pragma once

#include "core/errors.h"

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace hp {

/// @brief Appends values and arrays to `data`.
class BlobWriter {
  public:
    template <typename T>
    void put(const T& value) { bytes(&value, sizeof(T)); }
    /// @brief An array with its element count first (read back by BlobReader::array).
    template <typename T>
    void array(const std::vector<T>& v) {
        put(uint64_t(v.size()));
        raw(v);
    }
    /// @brief An array's elements alone (read back by BlobReader::raw with a count known otherwise).
    template <typename T>
    void raw(const std::vector<T>& v) { bytes(v.data(), v.size() * sizeof(T)); }
    void bytes(const void* p, size_t n) {
        const char* c = static_cast<const char*>(p);
        data.insert(data.end(), c, c + n);
    }
    std::vector<char> data;
};

/// @brief Reads what a BlobWriter wrote, in the same order; every read past
/// the end, size mismatch or leftover byte calls fail(), which by default
/// throws hp::Error naming `what` and the checkpoint.
class BlobReader {
  public:
    BlobReader(const std::vector<char>& data, std::string what) : data_(data), what_(std::move(what)) {}
    virtual ~BlobReader() = default;

    template <typename T>
    T get() {
        T value;
        bytes(&value, sizeof(T));
        return value;
    }
    /// @brief Reads a size-prefixed array that must have `expected` elements (the reader's own size).
    template <typename T>
    void array(std::vector<T>& v, size_t expected) {
        const uint64_t n = get<uint64_t>();
        if (n != expected) fail(cat("holds ", n, " values where ", expected, " are expected"));
        raw(v, n);
    }
    /// @brief Reads `count` elements written by BlobWriter::raw.
    template <typename T>
    void raw(std::vector<T>& v, uint64_t count) {
        if (count > remaining() / sizeof(T)) fail("truncated (arrays extend past the end of the data)");
        v.resize(count);
        bytes(v.data(), count * sizeof(T));
    }
    void bytes(void* p, size_t n) {
        if (n > remaining()) fail("truncated");
        if (n == 0) return;  // an empty array's data() may be null: memcpy(nullptr, ..., 0) is UB (UBSan)
        std::memcpy(p, data_.data() + pos_, n);
        pos_ += n;
    }
    size_t remaining() const { return data_.size() - pos_; }
    /// @brief Throws unless every byte was read.
    void finish() const {
        if (pos_ != data_.size()) fail("has trailing data");
    }
    /// @brief Reports a malformed blob: `why` completes "<what>: checkpoint ...".
    [[noreturn]] virtual void fail(const std::string& why) const { throw Error(what_ + ": checkpoint " + why); }

  private:
    const std::vector<char>& data_;
    std::string what_;
    size_t pos_ = 0;
};

}  // namespace hp
