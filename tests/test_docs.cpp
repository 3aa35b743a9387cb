// The documentation's own links: every relative link in the repository's
// Markdown files (README.md, docs/, each folder's README) names a file that
// exists, and a link to a heading (#anchor) names a heading of that file, so
// moving or renaming a chapter or a section cannot leave a dead link behind.
#include "test_support.h"

#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace hp::test;

namespace {

/// Text without its fenced code blocks (``` ... ```): links and headings
/// there are examples, not part of the page.
std::string withoutCodeBlocks(const std::string& text) {
    std::string out;
    bool fenced = false;
    size_t start = 0;
    while (start < text.size()) {
        size_t end = text.find('\n', start);
        if (end == std::string::npos) end = text.size();
        const std::string line = text.substr(start, end - start);
        const size_t first = line.find_first_not_of(' ');
        if (first != std::string::npos && line.compare(first, 3, "```") == 0) fenced = !fenced;
        else if (!fenced) out += line + "\n";
        start = end + 1;
    }
    return out;
}

/// GitHub's anchor of a heading: lower case, characters other than letters,
/// digits, '-', '_' and spaces dropped (non-ASCII letters kept), spaces
/// turned into '-'.
std::string anchorOf(const std::string& heading) {
    std::string a;
    for (unsigned char c : heading) {
        if (c >= 0x80 || std::isalnum(c) || c == '-' || c == '_') a += char(c >= 0x80 ? c : std::tolower(c));
        else if (c == ' ') a += '-';
    }
    return a;
}

std::set<std::string> anchorsOf(const fs::path& file) {
    std::set<std::string> anchors;
    static const std::regex heading(R"(#+\s+(.*?)\s*)");
    std::istringstream text(withoutCodeBlocks(readFile(file)));
    std::smatch m;
    for (std::string line; std::getline(text, line);)
        if (std::regex_match(line, m, heading)) anchors.insert(anchorOf(m[1].str()));
    return anchors;
}

/// The repository's Markdown files, outside build folders and hidden ones.
std::vector<fs::path> markdownFiles() {
    std::vector<fs::path> files;
    const fs::path root = sourcePath("");
    for (auto it = fs::recursive_directory_iterator(root); it != fs::recursive_directory_iterator(); ++it) {
        const std::string name = it->path().filename().string();
        if (it->is_directory() && (name.rfind("build", 0) == 0 || name.rfind('.', 0) == 0 || name == "out")) {
            it.disable_recursion_pending();
            continue;
        }
        if (it->is_regular_file() && it->path().extension() == ".md") files.push_back(it->path());
    }
    return files;
}

}  // namespace

TEST(Docs, EveryRelativeLinkResolves) {
    // [text](target) and [text](target "title"); absolute URLs are not checked.
    static const std::regex link(R"(\]\(([^)\s]+)(\s+"[^"]*")?\))");
    const std::vector<fs::path> files = markdownFiles();
    ASSERT_GE(files.size(), 10u) << "README.md, docs/ and the folders' READMEs";
    size_t checked = 0;
    for (const fs::path& file : files) {
        const std::string text = withoutCodeBlocks(readFile(file));
        for (std::sregex_iterator it(text.begin(), text.end(), link), end; it != end; ++it) {
            const std::string target = (*it)[1].str();
            if (std::regex_search(target, std::regex("^[a-z]+:"))) continue;  // http:, https:, mailto:
            ++checked;
            const size_t hash = target.find('#');
            const std::string path = target.substr(0, hash);
            const fs::path resolved = path.empty() ? file : (file.parent_path() / path).lexically_normal();
            if (!fs::exists(resolved)) {
                ADD_FAILURE() << file.string() << ": link to a missing file: " << target;
                continue;
            }
            if (hash != std::string::npos && resolved.extension() == ".md") {
                const std::string anchor = target.substr(hash + 1);
                EXPECT_EQ(anchorsOf(resolved).count(anchor), 1u)
                    << file.string() << ": link to a missing heading: " << target;
            }
        }
    }
    EXPECT_GE(checked, 50u) << "the pages' links were found";
}

TEST(Docs, AnchorsFollowGitHubsRule) {
    EXPECT_EQ(anchorOf("Batches and farms"), "batches-and-farms");
    EXPECT_EQ(anchorOf("B-render: time, `spp` (1080p)"), "b-render-time-spp-1080p");
    EXPECT_EQ(anchorOf("Gomes 2024, Table 5.1"), "gomes-2024-table-51");
}
