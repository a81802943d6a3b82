// Hostile scene input: files that are not files, includes and `$name` values that multiply, counts
// that only show at render setup. Each must end in one located facet::Error within seconds and a
// bounded amount of memory, never in a hang, std::bad_alloc or an error without a location.
// The inputs are generated here; the slow or memory-hungry cases run in a child process with a
// CPU-time and address-space limit, so that a regression fails instead of hanging the suite.

#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <future>
#include <string>
#include <unistd.h>

using namespace facet;
namespace fs = std::filesystem;

#define EXPECT_CONTAINS(text, part)                                                                \
    EXPECT_NE(std::string(text).find(part), std::string::npos) << "message: " << (text)

namespace {

class TempDir {
public:
    TempDir() {
        static int counter = 0;
        m_path = fs::temp_directory_path() /
                 fmt::format("facet_hostile_input_{}_{}", ::getpid(), counter++);
        fs::remove_all(m_path);
        fs::create_directories(m_path);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(m_path, ec);
    }
    std::string write(const std::string &name, const std::string &text) const {
        std::ofstream(m_path / name, std::ios::binary) << text;
        return (m_path / name).string();
    }
    std::string path(const std::string &name) const { return (m_path / name).string(); }

private:
    fs::path m_path;
};

/// The facet::Error of `fn`, or a test failure.
template <typename Fn> Error error_of(Fn fn) {
    try {
        fn();
    } catch (const Error &e) {
        return e;
    } catch (const std::exception &e) {
        ADD_FAILURE() << "expected a facet::Error, got " << typeid(e).name() << ": " << e.what();
        return Error("");
    }
    ADD_FAILURE() << "expected a facet::Error";
    return Error("");
}

bool under_address_sanitizer() {
#if defined(__SANITIZE_ADDRESS__)
    return true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
    return true;
#endif
#endif
    return false;
}

/// In a child process limited to 20 s of CPU time and (without AddressSanitizer, which reserves
/// terabytes of address space) `extra_mib` MiB more address space than it has: `fn` must throw a
/// facet::Error whose message contains `needle`, located in a file whose name contains `file` (or,
/// when `file` is null, without a location: the scene file itself is named in the message).
/// Exits 0 when it does; a hang or a runaway allocation ends the child by a signal.
template <typename Fn> [[noreturn]] void child_expects_error(Fn fn, const char *file,
                                                             const char *needle, size_t extra_mib) {
    const rlimit cpu{20, 20};
    if (::setrlimit(RLIMIT_CPU, &cpu) != 0) std::_Exit(2);
    if (!under_address_sanitizer()) {
        long pages = 0;
        std::ifstream("/proc/self/statm") >> pages;
        const rlim_t limit =
            rlim_t(pages) * rlim_t(::sysconf(_SC_PAGESIZE)) + (rlim_t(extra_mib) << 20);
        const rlimit as{limit, limit};
        if (::setrlimit(RLIMIT_AS, &as) != 0) std::_Exit(2);
    }
    try {
        fn();
    } catch (const Error &e) {
        std::fprintf(stderr, "%s\n", e.what());
        const bool located = file ? e.location().valid() && e.location().line > 0 &&
                                        e.location().file.find(file) != std::string::npos
                                  : true;
        std::_Exit(located && std::strstr(e.what(), needle) ? 0 : 3);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "not a facet::Error: %s\n", e.what());
        std::_Exit(4);
    }
    std::_Exit(5);
}

#define EXPECT_LOCATED_ERROR_IN_CHILD(fn, file, needle, extra_mib)                                 \
    do {                                                                                           \
        GTEST_FLAG_SET(death_test_style, "threadsafe");                                            \
        EXPECT_EXIT(child_expects_error(fn, file, needle, extra_mib),                              \
                    ::testing::ExitedWithCode(0), "");                                             \
    } while (0)

} // namespace

// -- Files that are not regular files -----------------------------------------------------------

TEST(HostileInput, DirectoriesDevicesAndFifosAreNotSceneFiles) {
    TempDir dir;
    const std::string folder = dir.path("folder.xml");
    fs::create_directories(folder);
    // "No document element found" said nothing about the cause.
    Error e = error_of([&] { load_file(folder); });
    EXPECT_CONTAINS(e.what(), "is a directory");
    EXPECT_CONTAINS(e.what(), folder);

    if (fs::exists("/dev/zero")) // read until memory ran out
        EXPECT_LOCATED_ERROR_IN_CHILD([] { load_file("/dev/zero"); }, nullptr,
                                      "\"/dev/zero\": it is a character device, not a regular file",
                                      512);

    // A FIFO blocked the loader forever. Should it block again, a writer that opens and closes
    // the FIFO after 10 s releases it, and the test fails instead of hanging.
    const std::string fifo = dir.path("fifo.xml");
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    auto loading = std::async(std::launch::async, [&] {
        try {
            load_file(fifo);
        } catch (const Error &err) {
            return std::string(err.what());
        }
        return std::string("no error");
    });
    if (loading.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
        ADD_FAILURE() << "loading a FIFO blocks";
        int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
        if (fd >= 0) ::close(fd);
    }
    std::string msg = loading.get();
    EXPECT_CONTAINS(msg, "is a FIFO, not a regular file");

    // Included, they are refused at the <include>.
    const std::string scene =
        dir.write("scene.xml", "<scene version=\"3.0.0\">\n  <include filename=\"fifo.xml\"/>\n"
                               "</scene>\n");
    e = error_of([&] { load_file(scene); });
    EXPECT_EQ(e.location().to_string(), scene + ":2:4");
    EXPECT_CONTAINS(e.message(), "is a FIFO");
    dir.write("scene.xml", "<scene version=\"3.0.0\">\n\n  <include filename=\"folder.xml\"/>\n"
                           "</scene>\n");
    e = error_of([&] { load_file(scene); });
    EXPECT_EQ(e.location().to_string(), scene + ":3:4");
    EXPECT_CONTAINS(e.message(), "is a directory");
}

TEST(HostileInput, SceneFilesHaveASizeLimit) {
    // A sparse file: 257 MiB long, nothing written but its first line.
    TempDir dir;
    const std::string big = dir.write("big.xml", "<scene version=\"3.0.0\">\n");
    fs::resize_file(big, (size_t(257) << 20));
    EXPECT_LOCATED_ERROR_IN_CHILD([&] { load_file(big); }, nullptr,
                                  "big.xml\" is 257.0 MiB, more than the limit of 256 MiB", 512);

    const std::string scene =
        dir.write("scene.xml", "<scene version=\"3.0.0\">\n  <include filename=\"big.xml\"/>\n"
                               "</scene>\n");
    EXPECT_LOCATED_ERROR_IN_CHILD([&] { load_file(scene); }, "scene.xml",
                                  "is 257.0 MiB, more than the limit of 256 MiB", 512);
}

// -- Budgets of a load ---------------------------------------------------------------------------

TEST(HostileInput, FilesThatIncludeEachOtherManyTimesHitTheIncludeBudget) {
    // f0 includes f1 ten times, f1 includes f2 ten times, ... f7: 10^7 inclusions without a
    // cycle (a million files parsed and 3.6 GB before the budget existed).
    TempDir dir;
    for (int i = 0; i < 8; ++i) {
        std::string xml = "<scene version=\"3.0.0\">\n";
        if (i < 7)
            for (int k = 0; k < 10; ++k)
                xml += fmt::format("  <include filename=\"f{}.xml\"/>\n", i + 1);
        dir.write(fmt::format("f{}.xml", i), xml + "</scene>\n");
    }
    const std::string top = dir.path("f0.xml");
    EXPECT_LOCATED_ERROR_IN_CHILD([&] { load_file(top); }, ".xml",
                                  "more than 100000 inclusions of files", 1024);
}

TEST(HostileInput, ElementsReadAgainThroughRepeatedIncludesHaveABudget) {
    // 40 x 40 inclusions of a file of 1,000 elements: 1.6 million elements from 1,000 written.
    TempDir dir;
    std::string leaf = "<scene version=\"3.0.0\">\n";
    for (int k = 0; k < 1000; ++k) leaf += "  <default name=\"x\" value=\"1\"/>\n";
    dir.write("leaf.xml", leaf + "</scene>\n");
    std::string mid = "<scene version=\"3.0.0\">\n", top = mid;
    for (int k = 0; k < 40; ++k) {
        mid += "  <include filename=\"leaf.xml\"/>\n";
        top += "  <include filename=\"mid.xml\"/>\n";
    }
    dir.write("mid.xml", mid + "</scene>\n");
    const std::string top_path = dir.write("top.xml", top + "</scene>\n");
    EXPECT_LOCATED_ERROR_IN_CHILD([&] { load_file(top_path); }, "leaf.xml",
                                  "more than 1000000 elements again", 1024);
    // Once each, the same files load.
    dir.write("mid.xml", "<scene version=\"3.0.0\"><include filename=\"leaf.xml\"/></scene>\n");
    dir.write("top.xml", "<scene version=\"3.0.0\"><include filename=\"mid.xml\"/></scene>\n");
    EXPECT_TRUE(load_file(top_path));
}

TEST(HostileInput, RepeatedIncludesOfALargeFileHitTheByteBudget) {
    // 1 MiB of comments included 1,100 times: 1.1 GiB of XML to walk through.
    TempDir dir;
    std::string big = "<scene version=\"3.0.0\">\n";
    const std::string comment = "<!-- " + std::string(1016, 'x') + " -->\n";
    while (big.size() < (size_t(1) << 20)) big += comment;
    dir.write("big.xml", big + "</scene>\n");
    std::string top = "<scene version=\"3.0.0\">\n";
    for (int k = 0; k < 1100; ++k) top += "  <include filename=\"big.xml\"/>\n";
    const std::string top_path = dir.write("top.xml", top + "</scene>\n");
    Error e = error_of([&] { load_file(top_path); });
    EXPECT_EQ(e.location().file, top_path);
    EXPECT_GT(e.location().line, 1000);
    EXPECT_CONTAINS(e.message(), "including \"big.xml\"");
    EXPECT_CONTAINS(e.message(), "past 1024 MiB");
}

TEST(HostileInput, DefaultsThatGrowTenfoldHitTheExpansionBudget) {
    // $a is ten copies of $b, ... $j ten characters: 10^10 bytes (a bad_alloc after 1 GB).
    const std::string names = "abcdefghij";
    std::string xml = "<scene version=\"3.0.0\">\n<default name=\"j\" value=\"xxxxxxxxxx\"/>\n";
    for (int i = 8; i >= 0; --i) {
        std::string value;
        for (int k = 0; k < 10; ++k) value += std::string("$") + names[size_t(i + 1)];
        xml += fmt::format("<default name=\"{}\" value=\"{}\"/>\n", names[size_t(i)], value);
    }
    xml += "<string name=\"s\" value=\"$a\"/>\n</scene>\n";
    EXPECT_LOCATED_ERROR_IN_CHILD([&] { load_string(xml); }, "string", "longer than 1 MiB", 512);
    Error e = error_of([&] { load_string(xml); });
    EXPECT_EQ(e.location().line, 8); // <default name="d">: 10^6 bytes are fine, 10^7 are not
}

TEST(HostileInput, SubstitutedTextHasABudgetPerScene) {
    // Each <default> of a defined name is ignored, but its value was substituted first: 600
    // copies of 512 KiB, 300 MiB of copying, stored nowhere.
    std::string xml = "<scene version=\"3.0.0\">\n<default name=\"big\" value=\"" +
                      std::string(size_t(512) << 10, 'x') + "\"/>\n";
    for (int k = 0; k < 600; ++k) xml += "<default name=\"big\" value=\"$big\"/>\n";
    Error e = error_of([&] { load_string(xml + "</scene>\n"); });
    EXPECT_EQ(e.location().file, "string");
    EXPECT_GT(e.location().line, 500);
    EXPECT_CONTAINS(e.message(), "more than 256 MiB of text");
}

TEST(HostileInput, OutOfMemoryWhileLoadingNamesTheElement) {
    // Within every budget, but more than the 128 MiB the child may allocate: 300 strings of
    // 512 KiB each. std::bad_alloc left the loader without a location.
    if (under_address_sanitizer())
        GTEST_SKIP()
            << "AddressSanitizer reserves terabytes of address space: no RLIMIT_AS under it";
    std::string xml = "<scene version=\"3.0.0\">\n<default name=\"big\" value=\"" +
                      std::string(size_t(512) << 10, 'x') + "\"/>\n<bsdf type=\"diffuse\">\n";
    for (int k = 0; k < 300; ++k) xml += fmt::format("<string name=\"s{}\" value=\"$big\"/>\n", k);
    xml += "</bsdf></scene>\n";
    EXPECT_LOCATED_ERROR_IN_CHILD([&] { load_string(xml); }, "string",
                                  "out of memory while reading", 128);
}

// -- One warning per kind of problem -------------------------------------------------------------

TEST(HostileInput, PlyPropertiesOfOneKindGiveOneWarning) {
    // 100,000 properties that fit no attribute printed 100,000 warnings (and the search for
    // names seen before was quadratic in them).
    TempDir dir;
    std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
                      "property float x\nproperty float y\nproperty float z\n";
    const int unknown = 100000;
    for (int i = 0; i < unknown; ++i) ply += fmt::format("property uchar quality{}\n", i);
    ply += "property list uchar float weights\n"
           "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    const float pos[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    for (const auto &p : pos) {
        ply.append(reinterpret_cast<const char *>(p), sizeof(p));
        ply.append(size_t(unknown), '\0');
        ply += '\0'; // an empty list
    }
    ply += '\3';
    for (int32_t i : {0, 1, 2}) ply.append(reinterpret_cast<const char *>(&i), sizeof(i));
    const std::string path = dir.write("many.ply", ply);

    Properties props("ply");
    props.set_string("filename", path);
    const size_t before = Logger::warning_count();
    ::testing::internal::CaptureStderr();
    auto shape = PluginRegistry::instance().create(ObjectType::Shape, props);
    const std::string log = ::testing::internal::GetCapturedStderr();
    EXPECT_TRUE(shape);
    EXPECT_EQ(Logger::warning_count() - before, 2u) << log;
    EXPECT_CONTAINS(log,
                    "100000 properties of element vertex ignored (attributes are named "
                    "<name>_<one-letter suffix>): \"quality0\", \"quality1\", \"quality2\", ...");
    EXPECT_CONTAINS(log, "list property \"weights\" of element vertex ignored");
}

// -- Errors at render setup ----------------------------------------------------------------------

TEST(HostileInput, SamplerErrorsAtRenderSetupCarryTheSamplersLocation) {
    // Strength 8 with 4 samples loads (2^8 rows); 1,000 samples per pixel given to the render
    // need 37^8 rows, more than 32 bits: the error had no location.
    const std::string xml = "<scene version=\"3.0.0\">\n"
                            "<sensor type=\"perspective\">\n"
                            "  <film type=\"hdrfilm\"><integer name=\"width\" value=\"4\"/>"
                            "<integer name=\"height\" value=\"4\"/></film>\n"
                            "  <sampler type=\"orthogonal\">\n"
                            "    <integer name=\"strength\" value=\"8\"/>\n"
                            "    <integer name=\"sample_count\" value=\"4\"/>\n"
                            "  </sampler>\n"
                            "</sensor>\n</scene>\n";
    auto scene = std::dynamic_pointer_cast<Scene>(load_string(xml));
    ASSERT_TRUE(scene);
    RenderOptions opts;
    opts.spp = 1000;
    Error e = error_of([&] { render_sample_range(*scene->sensors().at(0), opts); });
    EXPECT_EQ(e.location().to_string(), "string:4:4");
    EXPECT_CONTAINS(e.message(), "37^8 array rows do not fit 32 bits");
}

TEST(HostileInput, IntegratorErrorsAtRenderSetupCarryTheIntegratorsLocation) {
    // samples_per_pass 3 loads; a render of 4 samples per pixel cannot be split into passes of
    // 3: the error had no location. The light tracer's own check likewise.
    for (const char *type : {"path", "ptracer"}) {
        SCOPED_TRACE(type);
        const std::string xml = std::string("<scene version=\"3.0.0\">\n") +
                                "<sensor type=\"perspective\">\n"
                                "  <film type=\"hdrfilm\"><integer name=\"width\" value=\"4\"/>"
                                "<integer name=\"height\" value=\"4\"/></film>\n"
                                "</sensor>\n"
                                "  <integrator type=\"" +
                                type +
                                "\">\n"
                                "    <integer name=\"samples_per_pass\" value=\"3\"/>\n"
                                "  </integrator>\n"
                                "<shape type=\"sphere\"/><emitter type=\"constant\"/>\n"
                                "</scene>\n";
        auto scene = std::dynamic_pointer_cast<Scene>(load_string(xml));
        ASSERT_TRUE(scene);
        RenderOptions opts;
        opts.spp = 4;
        opts.progress = false;
        Error e = error_of([&] { render(*scene, *scene->sensors().at(0), opts); });
        EXPECT_EQ(e.location().to_string(), "string:5:4");
        EXPECT_CONTAINS(e.message(), "must be a multiple of samples_per_pass (3)");
    }
}
