// hairpipe's small error vocabulary (after pbrt-v4's error.h).
//
// Libraries throw these; only the CLI's main catches them and maps them to exit
// codes (see tools/hairpipe.cpp): UsageError, SceneError and AssetError -> 1,
// a frame that failed while others went on -> 2 (reported by the scheduler).
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace hp {

/// Where something came from in a scene file (1-based line and column).
struct SourceLocation {
    std::string file;
    int line = 0;
    int column = 0;

    bool valid() const { return !file.empty(); }
    /// "scene.yaml:12:5", or just the file name when line is unknown.
    std::string str() const;
};

/// Base of every error hairpipe reports to the user.
class Error : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

/// The command line is wrong (unknown option, bad frame range, ...).
class UsageError : public Error {
  public:
    using Error::Error;
};

/// A scene key is wrong: the message names file:line:column and the key path.
class SceneError : public Error {
  public:
    SceneError(const SourceLocation& where, const std::string& key, const std::string& message);
    const SourceLocation& where() const { return where_; }
    const std::string& key() const { return key_; }
    const std::string& detail() const { return detail_; }

  private:
    SourceLocation where_;
    std::string key_;
    std::string detail_;
};

/// A missing or broken input file (mesh, texture, cache frame): names the file.
class AssetError : public Error {
  public:
    AssetError(const std::string& file, const std::string& problem);
    const std::string& file() const { return file_; }

  private:
    std::string file_;
};

/// An output could not be written (permissions, full disk, ...).
class IoError : public Error {
  public:
    IoError(const std::string& file, const std::string& problem);
    const std::string& file() const { return file_; }
    const std::string& problem() const { return problem_; }

  private:
    std::string file_;
    std::string problem_;
};

/// A stage could not produce a frame (NaN in the solver, GL failure, ...).
class FrameError : public Error {
  public:
    using Error::Error;
};

/// Concatenates streamable values: cat("frame ", 12, " failed").
template <typename... Args>
std::string cat(const Args&... args) {
    std::ostringstream out;
    (out << ... << args);
    return out.str();
}

}  // namespace hp
