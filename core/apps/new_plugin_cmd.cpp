// `facet new-plugin bsdf <name> [dir]`: writes an out-of-tree plugin project that builds
// against the installed facet package and loads with -a.

#include "commands.h"

#include <facet/logger.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;

namespace {

const char *CMAKE_TEMPLATE = R"(# The @NAME@ plugin for facet, built out of tree:
#   cmake -S . -B build -DCMAKE_PREFIX_PATH=<facet's install prefix>
#   cmake --build build
#   facet plugins @NAME@ -a build            # its parameter table
#   facet chi2 bsdf @NAME@ -a build          # checks its sampling against its pdf
#   facet render scene.xml -a build          # or: export FACET_PLUGIN_PATH=$PWD/build
cmake_minimum_required(VERSION 3.20)
project(@NAME@ LANGUAGES CXX)

find_package(facet REQUIRED)
facet_add_plugin(@NAME@ @NAME@.cpp)
)";

// The plugin: a Lambertian BSDF, complete and correct, to be turned into something else. The
// doc block is what `facet plugins @NAME@` prints; keep its table in step with the constructor.
const char *BSDF_TEMPLATE = R"CPP(static const char *DOC = R"DOC(
# @NAME@: a BSDF plugin (so far a Lambertian reflector)

Describe the model here. Until you change it this is ideal diffuse reflection on the front side:
f = ρ/π, sampled cosine-weighted, so the sample weight is ρ.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| reflectance | spectrum or texture | 0.5 | Diffuse albedo ρ |

```xml
<bsdf type="@NAME@">
    <rgb name="reflectance" value="0.6, 0.4, 0.2"/>
</bsdf>
```
)DOC";

// Conventions (facet/bsdf.h): directions are in the local shading frame (normal +Z,
// cos θ = v.z); si.wi points away from the surface; eval() returns f·|cos θo|; sample() returns
// the weight f·|cos θo|/pdf (zero when it fails); pdf() is the density of exactly what sample()
// does. `facet chi2 bsdf @NAME@ -a <build dir>` checks all of this statistically.

#include <facet/bsdf.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>
#include <facet/warp.h>

#include <fmt/format.h>

namespace facet {

class @CLASS@ final : public BSDF {
public:
    explicit @CLASS@(const Properties &props) {
        // Read every parameter of the table, with its default; unread ones are reported.
        m_reflectance = props.texture("reflectance", 0.5f);
        BSDFFlags flags = BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide;
        if (m_reflectance->is_spatially_varying()) flags |= BSDFFlags::SpatiallyVarying;
        set_components({flags});
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float /*sample1*/, const Point2f &sample2) const override {
        BSDFSample bs;
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || Frame::cos_theta(si.wi) <= 0.f)
            return {bs, Color3f(0.f)};
        bs.wo = warp::square_to_cosine_hemisphere(sample2);
        bs.pdf = warp::square_to_cosine_hemisphere_pdf(bs.wo);
        bs.eta = 1.f;
        bs.sampled_type = BSDFFlags::DiffuseReflection;
        bs.sampled_component = 0;
        if (!(bs.pdf > 0.f) || Frame::cos_theta(bs.wo) <= 0.f) return {bs, Color3f(0.f)};
        return {bs, eval(ctx, si, bs.wo) / bs.pdf};
    }

    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || Frame::cos_theta(si.wi) <= 0.f ||
            Frame::cos_theta(wo) <= 0.f)
            return Color3f(0.f);
        return m_reflectance->eval(si) * (InvPi * Frame::cos_theta(wo));
    }

    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || Frame::cos_theta(si.wi) <= 0.f ||
            Frame::cos_theta(wo) <= 0.f)
            return 0.f;
        return warp::square_to_cosine_hemisphere_pdf(wo);
    }

    Color3f eval_diffuse_reflectance(const SurfaceInteraction &si) const override {
        return m_reflectance->eval(si);
    }

    std::string to_string() const override {
        return fmt::format("@CLASS@[reflectance = {}]", m_reflectance->to_string());
    }

private:
    std::shared_ptr<Texture> m_reflectance;
};

} // namespace facet

// Name = the XML type = the library's file name (@NAME@.so).
FACET_EXPORT_PLUGIN(facet::@CLASS@, BSDF, "@NAME@", "A BSDF plugin (so far a Lambertian reflector)", DOC)
)CPP";

std::string substitute(std::string text, const std::string &key, const std::string &value) {
    for (size_t at = text.find(key); at != std::string::npos;
         at = text.find(key, at + value.size()))
        text.replace(at, key.size(), value);
    return text;
}

/// "my_phong" -> "MyPhong".
std::string class_name(const std::string &name) {
    std::string out;
    bool upper = true;
    for (char c : name) {
        if (c == '_') {
            upper = true;
            continue;
        }
        out += upper ? char(std::toupper((unsigned char)c)) : c;
        upper = false;
    }
    return out;
}

void write_file(const fs::path &path, const std::string &text) {
    std::ofstream out(path);
    out << text;
    if (!out) FACET_THROW("cannot write \"{}\"", path.string());
}

} // namespace

int new_plugin_main(int argc, char **argv) {
    std::string kind, name, dir;
    bool force = false;
    CLI::App app("Write a new plugin project that builds out of tree against the installed facet "
                 "(CMakeLists.txt and one .cpp with a working plugin to start from)",
                 "facet new-plugin");
    app.add_option("kind", kind, "Kind of plugin (bsdf)")->required();
    app.add_option("name", name, "Plugin name: the XML type and the library file name")->required();
    app.add_option("dir", dir, "Folder to write (default: ./<name>)");
    app.add_flag("-f,--force", force, "Overwrite the files if they exist");
    if (int code = facet::cli::parse(app, argc, argv); code >= 0) return code;

    if (kind != "bsdf")
        FACET_THROW("facet new-plugin: no template for \"{}\" plugins (templates: bsdf)", kind);
    bool valid = !name.empty() && std::islower((unsigned char)name[0]);
    for (char c : name)
        valid =
            valid && (std::islower((unsigned char)c) || std::isdigit((unsigned char)c) || c == '_');
    if (!valid)
        FACET_THROW("plugin name \"{}\": use lower-case letters, digits and '_', starting with a "
                    "letter (it is the XML type and the file name)",
                    name);

    fs::path folder = dir.empty() ? fs::path(name) : fs::path(dir);
    fs::path cmake_file = folder / "CMakeLists.txt", source_file = folder / (name + ".cpp");
    for (const fs::path &p : {cmake_file, source_file})
        if (fs::exists(p) && !force)
            FACET_THROW("\"{}\" exists (use --force to overwrite it)", p.string());
    fs::create_directories(folder);

    std::string cmake = substitute(CMAKE_TEMPLATE, "@NAME@", name);
    std::string source =
        substitute(substitute(BSDF_TEMPLATE, "@NAME@", name), "@CLASS@", class_name(name));
    write_file(cmake_file, cmake);
    write_file(source_file, source);

    fmt::print("Wrote {} and {}. Build and test it with:\n"
               "  cmake -S {} -B {}/build -DCMAKE_PREFIX_PATH=<facet's install prefix>\n"
               "  cmake --build {}/build\n"
               "  facet chi2 bsdf {} -a {}/build\n",
               cmake_file.string(), source_file.string(), folder.string(), folder.string(),
               folder.string(), name, folder.string());
    return 0;
}
