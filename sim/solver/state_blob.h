// Byte blobs for solver checkpoints: plain arrays appended and read back in
// the same order, with sizes checked, so a restored solver holds exactly the
// bits it saved.
#pragma once

#include "core/bytes.h"
#include "core/errors.h"

#include <string>
#include <vector>

namespace hp {

/// Checkpoint arrays carry their element count, checked on restore.
class BlobWriter : public ByteWriter {
  public:
    template <typename T>
    void array(const std::vector<T>& v) { sized(v); }
};

class BlobReader : public ByteReader {
  public:
    BlobReader(const std::vector<char>& data, std::string what)
        : ByteReader(data, [what](const std::string& why) { throw Error(what + ": checkpoint is " + why); }) {}
    /// Reads an array that must have `expected` elements (the solver's own size).
    template <typename T>
    void array(std::vector<T>& v, size_t expected) {
        const uint64_t n = get<uint64_t>();
        if (n != expected) fail(cat("holding ", n, " values where ", expected, " are expected"));
        values(v, n);
    }
    void finish() const {
        if (remaining() != 0) fail("followed by trailing data");
    }
};

}  // namespace hp
