// Every image the README shows is in the repository: present in the source tree, small, and
// (in a git checkout) tracked rather than ignored.

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

std::vector<std::string> readme_images() {
    std::ifstream in(fs::path(FACET_SOURCE_DIR) / "README.md");
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string text = ss.str();
    std::vector<std::string> paths;
    // Markdown images ![alt](path) and HTML <img src="path">, local files only.
    const std::regex image(R"re(!\[[^\]]*\]\(([^)\s]+)\)|<img[^>]*src="([^"]+)")re");
    for (auto it = std::sregex_iterator(text.begin(), text.end(), image);
         it != std::sregex_iterator(); ++it) {
        std::string p = (*it)[1].matched ? (*it)[1].str() : (*it)[2].str();
        if (p.rfind("http://", 0) == 0 || p.rfind("https://", 0) == 0) continue;
        paths.push_back(p);
    }
    return paths;
}

/// Output of a shell command, or "" when it fails.
std::string command_output(const std::string &cmd) {
    std::string out;
    if (FILE *p = popen(cmd.c_str(), "r")) {
        char buf[4096];
        size_t n;
        while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
        if (pclose(p) != 0) return "";
    }
    return out;
}

} // namespace

TEST(ReadmeImages, EveryReferencedImageIsInTheRepository) {
    const std::vector<std::string> images = readme_images();
    ASSERT_FALSE(images.empty()) << "the README shows no image: the parser is broken";
    const fs::path src(FACET_SOURCE_DIR);
    for (const std::string &image : images) {
        const fs::path p = src / image;
        ASSERT_TRUE(fs::is_regular_file(p)) << image << " is shown by the README but missing";
        EXPECT_LT(fs::file_size(p), 100u * 1024u) << image << ": keep README images small";
    }
    if (!fs::exists(src / ".git")) {
        std::printf("not a git checkout: only the presence of the images was checked\n");
        return;
    }
    for (const std::string &image : images) {
        const std::string tracked =
            command_output("git -C '" + src.string() + "' ls-files -- '" + image + "' 2>/dev/null");
        const std::string ignored =
            command_output("git -C '" + src.string() + "' check-ignore -q -- '" + image +
                           "' 2>/dev/null && echo ignored");
        EXPECT_TRUE(!tracked.empty() || ignored.empty())
            << image << " is ignored by .gitignore, so a commit would leave it out";
    }
}
