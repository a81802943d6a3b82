// A plugin author's own test, built out of tree against facet::testing: the chi-square test of
// the phong plugin's sampling at a few incident angles, through the library rather than the
// `facet chi2` command. Usage: phong_chi2 <folder of phong.so>; exits with 1 on rejection.

#include <facet/chi2.h>
#include <facet/plugin.h>
#include <facet/properties.h>

#include <cstdio>

int main(int argc, char **argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: phong_chi2 <folder of phong.so>\n");
        return 2;
    }
    facet::PluginRegistry::instance().add_search_dir(argv[1]);
    const float angles[] = {20.f, 75.f};
    bool ok = true;
    for (float theta : angles) {
        facet::Properties props("phong");
        props.set_float("exponent", 80.0);
        facet::BSDFAdapter adapter(props, facet::direction_from_angles(theta, 30.f));
        facet::Chi2Options opts;
        opts.samples = 300000;
        opts.test_count = 2;
        facet::Chi2Result result = facet::run_chi2(adapter, opts);
        std::printf("%s", result.summary().c_str());
        ok = ok && result.passed;
    }
    return ok ? 0 : 1;
}
