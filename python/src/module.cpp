// facet._facet: the compiled half of the `facet` Python package (python/facet/__init__.py is the
// public API). Loads scenes, renders them with the GIL released (Ctrl-C cancels the render and
// raises KeyboardInterrupt), writes images through facet's writer, lists plugins, runs the
// chi-square test of facet::testing and merges render parts (facet/merge.h).

#include <facet/chi2.h>
#include <facet/film.h>
#include <facet/image.h>
#include <facet/logger.h>
#include <facet/merge.h>
#include <facet/mode.h>
#include <facet/output_metadata.h>
#include <facet/params.h>
#include <facet/plugin.h>
#include <facet/render.h>
#include <facet/sampler.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <iterator>
#include <mutex>
#include <optional>
#include <thread>

namespace py = pybind11;
namespace fs = std::filesystem;
using namespace facet;

namespace {

/// A loaded scene and where it came from (the `facet:scene` metadata of its renders).
struct PyScene {
    std::shared_ptr<Scene> scene;
    std::string path; ///< absolute file name; empty for load_string
    std::map<std::string, std::string> params;
    std::string text;  ///< the XML, for facet:scene_hash (as `facet render` computes it)
    std::string edits; ///< the values traverse() changed, in order (also in facet:scene_hash)
};

std::string file_text(const std::string &path) {
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// A path argument, refused when it holds a NUL character: the C++ side would read it only up to
/// the NUL, a different file than the one named.
const std::string &checked_path(const std::string &path, const char *what) {
    if (path.find('\0') != std::string::npos) {
        std::string shown = path;
        for (size_t at; (at = shown.find('\0')) != std::string::npos;) shown.replace(at, 1, "\\0");
        throw py::value_error(
            fmt::format("{}: the path \"{}\" contains a NUL character", what, shown));
    }
    return path;
}

LoadOptions load_options(const std::map<std::string, std::string> &params, bool lenient,
                         const std::vector<std::string> &search_path,
                         const std::optional<std::string> &mode) {
    for (const std::string &dir : search_path) checked_path(dir, "search_path");
    LoadOptions opts;
    opts.params = params;
    opts.lenient = lenient;
    opts.search_path = search_path;
    // Resolved here, with the GIL held: the note of a vectorised name is logged once.
    opts.mode = mode ? resolve_mode(*mode) : default_mode();
    return opts;
}

std::shared_ptr<Scene> as_scene(std::shared_ptr<Object> obj, const std::string &where) {
    auto scene = std::dynamic_pointer_cast<Scene>(obj);
    if (!scene)
        FACET_THROW("{}: the root element is a <{}>, not a <scene>", where,
                    object_type_name(obj->type()));
    return scene;
}

PyScene load_file_py(const std::string &path, const std::map<std::string, std::string> &params,
                     bool lenient, const std::vector<std::string> &search_path,
                     const std::optional<std::string> &mode) {
    checked_path(path, "load_file");
    LoadOptions opts = load_options(params, lenient, search_path, mode);
    if (!fs::exists(path)) FACET_THROW("scene file \"{}\" does not exist", path);
    PyScene s;
    s.path = fs::absolute(path).lexically_normal().string();
    s.params = params;
    py::gil_scoped_release release;
    // The loader first: it refuses what is not a regular file (a FIFO would block the read).
    s.scene = facet::load_scene(path, opts);
    s.text = file_text(path);
    return s;
}

PyScene load_string_py(const std::string &xml, const std::map<std::string, std::string> &params,
                       bool lenient, const std::vector<std::string> &search_path,
                       const std::optional<std::string> &mode) {
    PyScene s;
    s.params = params;
    LoadOptions opts = load_options(params, lenient, search_path, mode);
    py::gil_scoped_release release;
    s.scene = as_scene(facet::load_string(xml, opts), "string");
    return s;
}

py::array_t<float> to_array(const Image &img) {
    py::array_t<float> arr(
        {py::ssize_t(img.height), py::ssize_t(img.width), py::ssize_t(img.channels)});
    std::memcpy(arr.mutable_data(), img.data.data(), img.data.size() * sizeof(float));
    return arr;
}

Image from_array(const py::array_t<float, py::array::c_style | py::array::forcecast> &arr,
                 const std::vector<std::string> &channels) {
    if (arr.ndim() != 2 && arr.ndim() != 3)
        FACET_THROW("an image is an array of shape (height, width) or (height, width, channels), "
                    "not one with {} dimensions",
                    arr.ndim());
    int h = int(arr.shape(0)), w = int(arr.shape(1)), c = arr.ndim() == 3 ? int(arr.shape(2)) : 1;
    if (!channels.empty() && int(channels.size()) != c)
        FACET_THROW("{} channel names for an image of {} channels", channels.size(), c);
    Image img(w, h, c);
    img.channel_names = channels;
    std::memcpy(img.data.data(), arr.data(), img.data.size() * sizeof(float));
    return img;
}

/// Runs `fn` on a thread of its own while this thread waits with the GIL released, checking for
/// Python signals (Ctrl-C) every 50 ms when it is the main thread. On a signal, `cancel` is set,
/// the Python exception (KeyboardInterrupt) is kept in `interrupt`, and fn's result (the render
/// stopped early) is returned all the same, for the caller to attach to it; further Ctrl-C while
/// the render stops are absorbed (one KeyboardInterrupt, not one in the caller's handler too).
/// An error of fn after the signal gives way to the KeyboardInterrupt. `poll` (the progress
/// callback) runs with the GIL at the same times; an exception it raises stops the render the
/// same way and is kept in `interrupt` instead.
template <typename Fn> auto run_interruptible(std::atomic<bool> &cancel,
                                              std::optional<py::error_already_set> &interrupt,
                                              Fn fn, const std::function<void()> &poll = nullptr) {
    using R = decltype(fn());
    std::packaged_task<R()> task(std::move(fn));
    std::future<R> future = task.get_future();
    std::thread worker(std::move(task));
    for (;;) {
        bool ready;
        {
            py::gil_scoped_release release;
            ready = future.wait_for(std::chrono::milliseconds(50)) == std::future_status::ready;
        }
        if (ready) break;
        if (poll && !interrupt) {
            try {
                poll(); // the progress callback, with the GIL
            } catch (py::error_already_set &e) {
                interrupt.emplace(std::move(e)); // the callback raised: stop, and raise that
                cancel = true;
            }
        }
        if (PyErr_CheckSignals() != 0) {
            if (!interrupt) {
                interrupt.emplace(); // takes the KeyboardInterrupt
                cancel = true;
            } else {
                PyErr_Clear();
            }
        }
    }
    worker.join();
    if (!interrupt) return future.get(); // rethrows the render's exception
    try {
        return future.get();
    } catch (...) {
        throw *interrupt;
    }
}

/// A file's attributes as a Python dict: str, int and float values, and 4×4 matrices as a tuple
/// of their 4 rows.
py::dict metadata_dict(const FileMetadata &m) {
    py::dict d;
    for (const auto &[k, v] : m.strings) d[py::str(k)] = py::str(v);
    for (const auto &[k, v] : m.ints) d[py::str(k)] = py::int_(v);
    for (const auto &[k, v] : m.floats) d[py::str(k)] = py::float_(v);
    for (const auto &[k, v] : m.matrices)
        d[py::str(k)] = py::make_tuple(py::make_tuple(v.m[0][0], v.m[0][1], v.m[0][2], v.m[0][3]),
                                       py::make_tuple(v.m[1][0], v.m[1][1], v.m[1][2], v.m[1][3]),
                                       py::make_tuple(v.m[2][0], v.m[2][1], v.m[2][2], v.m[2][3]),
                                       py::make_tuple(v.m[3][0], v.m[3][1], v.m[3][2], v.m[3][3]));
    return d;
}

/// The attributes of a dict as metadata_dict() makes them (and any str values).
FileMetadata metadata_of(const py::dict &d) {
    FileMetadata m;
    for (const auto &[k, v] : d) {
        const std::string key = py::str(k);
        if (py::isinstance<py::str>(v)) {
            m.strings[key] = v.cast<std::string>();
        } else if (py::isinstance<py::bool_>(v)) {
            FACET_THROW("metadata {}: expected a str, int, float or 4x4 matrix, not a bool", key);
        } else if (py::isinstance<py::int_>(v)) {
            m.ints[key] = v.cast<int>();
        } else if (py::isinstance<py::float_>(v)) {
            m.floats[key] = v.cast<float>();
        } else {
            std::vector<std::vector<float>> rows;
            try {
                rows = v.cast<std::vector<std::vector<float>>>();
            } catch (const py::cast_error &) {}
            if (rows.size() != 4 ||
                std::any_of(rows.begin(), rows.end(), [](const auto &r) { return r.size() != 4; }))
                FACET_THROW("metadata {}: expected a str, int, float or 4x4 matrix", key);
            Matrix4f matrix;
            for (int i = 0; i < 4; ++i)
                for (int j = 0; j < 4; ++j) matrix.m[i][j] = rows[size_t(i)][size_t(j)];
            m.matrices[key] = matrix;
        }
    }
    return m;
}

py::tuple window_of(const Image &img) {
    return py::make_tuple(img.x, img.y, img.full_width > 0 ? img.full_width : img.x + img.width,
                          img.full_height > 0 ? img.full_height : img.y + img.height);
}

/// Returns (pixels, channel names, metadata, half, window).
py::tuple render_py(const PyScene &s, std::optional<int> spp, uint64_t seed, int sensor_index,
                    std::optional<int> threads, std::optional<std::array<int, 4>> crop,
                    int pass_index, int pass_count, const py::object &progress,
                    const std::optional<std::string> &mode) {
    // The scene's objects were built for one mode (load_file's mode=); a render in another
    // would need them built again.
    const std::string render_mode = mode_name(s.scene->mode());
    if (mode) {
        const std::string asked = resolve_mode(*mode); // logs a vectorised name's note once
        if (asked != render_mode)
            FACET_THROW("mode=\"{}\": the scene was loaded in {}; load it with mode=\"{}\" to "
                        "render it in that mode",
                        *mode, render_mode, asked);
    }
    const auto &sensors = s.scene->sensors();
    if (sensor_index < 0 || size_t(sensor_index) >= sensors.size())
        FACET_THROW("sensor {}: the scene has {} sensor{} (valid indices 0..{})", sensor_index,
                    sensors.size(), sensors.size() == 1 ? "" : "s", int(sensors.size()) - 1);
    if (spp && *spp < 1) FACET_THROW("spp={}: expected a positive number of samples", *spp);
    if (threads && *threads < 1) FACET_THROW("threads={}: expected at least 1", *threads);
    // Held until the render ends: no update() of the scene may free the sensor meanwhile.
    auto lock = std::make_shared<Scene::RenderLock>(*s.scene);
    const Sensor &sensor = *sensors[size_t(sensor_index)];

    RenderOptions opts;
    opts.threads = threads ? *threads : 0;
    opts.seed = seed;
    opts.spp = spp ? *spp : 0;
    // progress: True draws the CLI's bar (on a terminal), a callable gets the fraction done.
    const bool callback = !progress.is_none() && PyCallable_Check(progress.ptr());
    opts.progress = !callback && !progress.is_none() && progress.cast<bool>();
    auto fraction = std::make_shared<std::atomic<double>>(-1.0);
    if (callback) opts.on_progress = [fraction](double f) { fraction->store(f); };
    double reported = -1.0;
    std::function<void()> poll;
    if (callback)
        poll = [&]() {
            const double f = fraction->load();
            if (f > reported) {
                reported = f;
                progress(f);
            }
        };
    if (crop) opts.crop = *crop;
    opts.pass_index = pass_index;
    opts.pass_count = pass_count;
    std::atomic<bool> cancel{false};
    opts.cancel = &cancel;

    std::shared_ptr<Scene> keep = s.scene; // alive while the render thread runs
    std::optional<py::error_already_set> interrupt;
    RenderResult result = run_interruptible(
        cancel, interrupt, [keep, lock, &sensor, opts]() { return render(*keep, sensor, opts); },
        poll);
    if (callback && reported < 1.0 && !result.cancelled) progress(1.0);

    // The attributes `facet render` writes, so that parts from here and from the CLI merge.
    const std::string scene_hash =
        scene_identity(s.text + s.edits, s.params, result.film_width, result.film_height);
    const FileMetadata meta = render_file_metadata(
        render_file_info(result, sensor, scene_hash, s.path, seed, render_mode));
    py::tuple image =
        py::make_tuple(to_array(result.image), result.image.channel_names, metadata_dict(meta),
                       sensor.film().half(), window_of(result.image));
    if (interrupt) {
        // Ctrl-C stopped the render: the passes done go with the KeyboardInterrupt, as the
        // facet.Image `partial` (as `facet render` writes them to its output).
        try {
            interrupt->value().attr("partial") = py::module_::import("facet").attr("Image")(*image);
        } catch (py::error_already_set &) {
            interrupt->value().attr("partial") = image; // the module alone, without the package
        }
        throw *interrupt;
    }
    return image;
}

void write_py(const py::array_t<float, py::array::c_style | py::array::forcecast> &pixels,
              const std::vector<std::string> &channels, const std::string &path, bool half,
              const py::dict &metadata, const std::string &ocio_config, const std::string &display,
              const std::string &view, const std::string &looks, const std::array<int, 4> &window) {
    checked_path(path, "write");
    checked_path(ocio_config, "write: ocio_config");
    Image img = from_array(pixels, channels);
    img.x = window[0];
    img.y = window[1];
    img.full_width = window[2];
    img.full_height = window[3];
    ImageWriteOptions opts;
    opts.half = half;
    add_metadata(opts, metadata_of(metadata));
    opts.ocio_config = ocio_config;
    opts.display = display;
    opts.view = view;
    opts.looks = looks;
    py::gil_scoped_release release;
    write_image(path, img, opts);
}

py::tuple read_py(const std::string &path) {
    checked_path(path, "read");
    Image img;
    {
        py::gil_scoped_release release;
        img = read_image(path);
    }
    return py::make_tuple(to_array(img), img.channel_names);
}

/// Merges parts given as file names or as (pixels, channels, metadata, half, window) tuples;
/// returns (pixels, channels, metadata, half, window, passes).
py::tuple merge_py(const py::list &items) {
    std::vector<merge::Part> parts;
    for (size_t i = 0; i < items.size(); ++i) {
        py::handle item = items[i];
        if (py::isinstance<py::str>(item)) {
            std::string path = item.cast<std::string>();
            checked_path(path, "merge");
            py::gil_scoped_release release;
            parts.push_back(merge::read_part(path));
            continue;
        }
        auto t = item.cast<py::tuple>();
        if (t.size() != 5)
            FACET_THROW("part {}: expected a file name or a rendered facet.Image", i);
        merge::Part p;
        p.name = fmt::format("part {}", i);
        p.image =
            from_array(t[0].cast<py::array_t<float, py::array::c_style | py::array::forcecast>>(),
                       t[1].cast<std::vector<std::string>>());
        p.metadata = metadata_of(t[2].cast<py::dict>());
        p.half = t[3].cast<bool>();
        auto w = t[4].cast<std::array<int, 4>>();
        p.x = w[0];
        p.y = w[1];
        p.full_width = w[2];
        p.full_height = w[3];
        parts.push_back(std::move(p));
    }
    merge::Merged m;
    {
        py::gil_scoped_release release;
        m = merge::merge_parts(parts);
    }
    return py::make_tuple(to_array(m.image), m.image.channel_names, metadata_dict(m.metadata),
                          m.half, py::make_tuple(0, 0, m.image.width, m.image.height), m.passes);
}

/// [(name, kind, description, doc)] of every plugin on the search path.
std::vector<py::tuple> plugins_py() {
    PluginRegistry &registry = PluginRegistry::instance();
    std::vector<py::tuple> out;
    for (const std::string &name : registry.available()) {
        const PluginDescriptor &d = registry.descriptor(name);
        out.push_back(py::make_tuple(name, object_type_name(d.kind),
                                     d.description ? d.description : "", d.doc ? d.doc : ""));
    }
    return out;
}

Chi2Options chi2_options(const py::dict &o) {
    Chi2Options opts;
    opts.res = o["res"].cast<int>();
    opts.samples = o["samples"].cast<uint64_t>();
    opts.seed = o["seed"].cast<uint32_t>();
    opts.test_count = std::max(1u, o["tests"].cast<uint32_t>());
    opts.significance = o["significance"].cast<double>();
    opts.adaptive = o["adaptive"].cast<bool>();
    opts.ires = o["ires"].cast<int>();
    if (!(opts.significance > 0.0 && opts.significance < 1.0))
        FACET_THROW("significance={} must be in (0, 1)", opts.significance);
    if (opts.res < 2) FACET_THROW("res={}: expected at least 2 cells", opts.res);
    if (opts.samples < 1) FACET_THROW("samples must be positive");
    return opts;
}

Chi2Result run_adapter(const Chi2Adapter &adapter, const Chi2Options &opts) {
    py::gil_scoped_release release;
    return run_chi2(adapter, opts);
}

Vector3f vec3(const std::vector<float> &v, const char *what) {
    if (v.size() != 3) FACET_THROW("{} expects 3 numbers, got {}", what, v.size());
    return Vector3f(v[0], v[1], v[2]);
}

py::array_t<double> histogram(const std::vector<double> &v, int rows, int cols) {
    py::array_t<double> a({py::ssize_t(rows), py::ssize_t(cols)});
    if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(double));
    return a;
}

// -- traverse(): scene parameters ----------------------------------------------------------------

/// facet.traverse(scene): facet::SceneParameters and the Python scene whose renders it changes.
struct PyParams {
    PyScene *scene; ///< kept alive by the Python object (py::keep_alive)
    SceneParameters params;
};

py::object value_to_py(const Properties::Value &v) {
    return std::visit(
        [](const auto &x) -> py::object {
            using T = std::decay_t<decltype(x)>;
            if constexpr (std::is_same_v<T, bool>)
                return py::bool_(x);
            else if constexpr (std::is_same_v<T, int64_t>)
                return py::int_(x);
            else if constexpr (std::is_same_v<T, double>)
                return py::float_(x);
            else if constexpr (std::is_same_v<T, std::string>)
                return py::str(x);
            else if constexpr (std::is_same_v<T, Vector3f>)
                return py::make_tuple(x.x, x.y, x.z);
            else if constexpr (std::is_same_v<T, Color3f>)
                return py::make_tuple(x.r, x.g, x.b);
            else if constexpr (std::is_same_v<T, SpectrumData>) {
                if (x.uniform) return py::float_(x.value);
                py::list pairs;
                for (size_t i = 0; i < x.wavelengths.size(); ++i)
                    pairs.append(py::make_tuple(x.wavelengths[i], x.values[i]));
                return std::move(pairs);
            } else if constexpr (std::is_same_v<T, Transform>) {
                py::array_t<float> a({4, 4});
                for (int r = 0; r < 4; ++r)
                    for (int c = 0; c < 4; ++c) a.mutable_at(r, c) = x.matrix.m[r][c];
                return std::move(a);
            } else {
                return py::none();
            }
        },
        v);
}

bool is_number(const py::handle &h) {
    if (py::isinstance<py::bool_>(h)) return false;
    return py::isinstance<py::int_>(h) || py::isinstance<py::float_>(h) ||
           py::isinstance(h, py::module_::import("numbers").attr("Real"));
}

double as_float(const py::handle &h) {
    return py::float_(py::reinterpret_borrow<py::object>(h)).cast<double>();
}

int64_t as_int(const py::handle &h) {
    return py::int_(py::reinterpret_borrow<py::object>(h)).cast<int64_t>();
}

/// A 4x4 matrix from nested sequences, a NumPy array or an object with a `matrix` attribute.
std::optional<Transform> as_transform(const py::handle &h) {
    py::object obj = py::reinterpret_borrow<py::object>(h);
    if (py::hasattr(obj, "matrix")) obj = obj.attr("matrix");
    if (py::isinstance<py::str>(obj) || is_number(obj)) return std::nullopt;
    py::array_t<double, py::array::c_style | py::array::forcecast> a;
    try {
        a = obj.cast<py::array_t<double, py::array::c_style | py::array::forcecast>>();
    } catch (const py::cast_error &) {
        return std::nullopt;
    }
    if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4) return std::nullopt;
    float rows[16];
    for (int i = 0; i < 16; ++i) rows[i] = float(a.data()[i]);
    Transform t(Matrix4f::from_rows(rows));
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c)
            if (!std::isfinite(t.matrix.m[r][c]) || !std::isfinite(t.inverse_matrix.m[r][c]))
                FACET_THROW("the matrix is not an invertible transform with finite entries");
    return t;
}

std::optional<Vector3f> as_triple(const py::handle &h) {
    if (py::isinstance<py::str>(h) || !py::isinstance<py::sequence>(h)) {
        if (!py::hasattr(h, "__array__")) return std::nullopt;
    }
    std::vector<double> v;
    try {
        v = py::cast<std::vector<double>>(
            py::module_::import("numpy").attr("asarray")(h, "float64").attr("ravel")());
    } catch (const std::exception &) {
        return std::nullopt;
    }
    if (v.size() != 3) return std::nullopt;
    return Vector3f(float(v[0]), float(v[1]), float(v[2]));
}

/// The Python value as a value of type `want` (the parameter's), or of the type its form gives
/// when the scene leaves the parameter at its default (`want` empty).
Properties::Value value_from_py(const std::string &key, const py::handle &h,
                                std::optional<Properties::Type> want) {
    using T = Properties::Type;
    auto wrong = [&](const char *expected) {
        return Error(fmt::format("scene parameter \"{}\" expects {}, not {} {}", key, expected,
                                 std::string(py::str(py::type::of(h).attr("__name__"))),
                                 std::string(py::repr(h))));
    };
    if (!want) {
        if (py::isinstance<py::bool_>(h)) return h.cast<bool>();
        if (py::isinstance<py::int_>(h)) return h.cast<int64_t>();
        if (is_number(h)) return h.cast<double>();
        if (py::isinstance<py::str>(h)) return h.cast<std::string>();
        if (auto t = as_transform(h)) return *t;
        if (auto v = as_triple(h)) return Color3f(v->x, v->y, v->z);
        throw wrong("a bool, a number, a string, an rgb triple or a 4x4 transform");
    }
    switch (*want) {
    case T::Bool:
        if (!py::isinstance<py::bool_>(h) &&
            !py::isinstance(h, py::module_::import("numpy").attr("bool_")))
            throw wrong("a bool");
        return h.cast<bool>();
    case T::Integer:
        if (py::isinstance<py::bool_>(h) ||
            !py::isinstance(h, py::module_::import("numbers").attr("Integral")))
            throw wrong("an integer");
        return as_int(h);
    case T::Float:
        if (!is_number(h)) throw wrong("a number");
        return as_float(h);
    case T::String:
        if (!py::isinstance<py::str>(h)) throw wrong("a string");
        return h.cast<std::string>();
    case T::Vector:
        if (auto v = as_triple(h)) return *v;
        throw wrong("3 numbers");
    case T::Color:
        if (is_number(h)) return Color3f(float(as_float(h)));
        if (auto v = as_triple(h)) return Color3f(v->x, v->y, v->z);
        throw wrong("an rgb triple or a number");
    case T::Spectrum: {
        if (is_number(h)) return SpectrumData::constant(as_float(h));
        SpectrumData s;
        s.uniform = false;
        try {
            for (auto pair : h.cast<py::sequence>()) {
                auto p = pair.cast<std::pair<double, double>>();
                if (!s.wavelengths.empty() && !(p.first > s.wavelengths.back()))
                    FACET_THROW("scene parameter \"{}\": wavelengths must increase", key);
                s.wavelengths.push_back(p.first);
                s.values.push_back(p.second);
            }
        } catch (const py::cast_error &) {
            throw wrong("a number or (wavelength, value) pairs");
        }
        if (s.wavelengths.empty()) throw wrong("a number or (wavelength, value) pairs");
        return s;
    }
    case T::Transform:
        if (auto t = as_transform(h)) return *t;
        throw wrong("a 4x4 matrix");
    default:
        throw wrong("a value");
    }
}

void bind_params(py::module_ &m) {
    py::class_<PyParams>(m, "SceneParameters")
        .def("keys", [](const PyParams &p) { return p.params.keys(); })
        .def("has", [](const PyParams &p, const std::string &k) { return p.params.has(k); })
        .def("is_set", [](const PyParams &p, const std::string &k) { return p.params.is_set(k); })
        .def("get",
             [](const PyParams &p, const std::string &k) { return value_to_py(p.params.get(k)); })
        .def("type",
             [](const PyParams &p, const std::string &k) {
                 return std::string(Properties::type_name(p.params.type(k)));
             })
        .def("set",
             [](PyParams &p, const std::string &k, const py::handle &v) {
                 std::optional<Properties::Type> want;
                 if (p.params.is_set(k)) want = p.params.type(k);
                 Properties::Value value = value_from_py(k, v, want);
                 p.params.set(k, value);
                 p.scene->edits += fmt::format("\n{}={}", k, std::string(py::repr(v)));
             })
        .def("pending", [](const PyParams &p) { return p.params.pending(); })
        .def("update", [](PyParams &p) {
            SceneUpdate u;
            {
                py::gil_scoped_release release;
                u = p.params.update();
            }
            py::dict d;
            d["objects_created"] = u.objects_created;
            d["shapes_created"] = u.shapes_created;
            d["shapes_relinked"] = u.shapes_relinked;
            d["accel_rebuilt"] = u.accel_rebuilt;
            d["geometries_built"] = u.geometries_built;
            return d;
        });
    m.def(
        "traverse",
        [](PyScene &s) {
            return PyParams{&s, traverse(s.scene)};
        },
        py::arg("scene"), py::keep_alive<0, 1>());
}

/// The Python exception type for facet::Error (a RuntimeError with file, line and column).
PyObject *g_error_type = nullptr;

} // namespace

PYBIND11_MODULE(_facet, m) {
    m.doc() = "facet's compiled module; use the `facet` package";

    static py::exception<Error> error_type(m, "Error", PyExc_RuntimeError);
    g_error_type = error_type.ptr();
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const Error &e) {
            py::object exc = py::reinterpret_borrow<py::object>(g_error_type)(e.what());
            const Location &loc = e.location();
            exc.attr("file") = loc.valid() ? py::object(py::str(loc.file)) : py::none();
            exc.attr("line") = loc.valid() ? py::object(py::int_(loc.line)) : py::none();
            exc.attr("column") = loc.valid() ? py::object(py::int_(loc.column)) : py::none();
            PyErr_SetObject(g_error_type, exc.ptr());
        }
    });

    py::class_<PyScene>(m, "Scene", "A loaded scene (facet.load_file / facet.load_string)")
        .def_property_readonly("path", [](const PyScene &s) { return s.path; })
        .def_property_readonly("params", [](const PyScene &s) { return s.params; })
        .def_property_readonly("mode", [](const PyScene &s) { return mode_name(s.scene->mode()); })
        .def_property_readonly("sensor_count",
                               [](const PyScene &s) { return s.scene->sensors().size(); })
        .def(
            "film_size",
            [](const PyScene &s, int sensor) {
                const auto &sensors = s.scene->sensors();
                if (sensor < 0 || size_t(sensor) >= sensors.size())
                    FACET_THROW("sensor {}: the scene has {} sensors", sensor, sensors.size());
                const Film &f = sensors[size_t(sensor)]->film();
                return py::make_tuple(f.size().x, f.size().y);
            },
            py::arg("sensor") = 0, "(width, height) of the film of `sensor`")
        .def("__repr__", [](const PyScene &s) {
            return fmt::format("<facet.Scene {}>", s.path.empty() ? "(from a string)" : s.path);
        });

    bind_params(m);
    m.def("load_file", &load_file_py, py::arg("path"), py::arg("params"), py::arg("lenient"),
          py::arg("search_path"), py::arg("mode"));
    m.def("load_string", &load_string_py, py::arg("xml"), py::arg("params"), py::arg("lenient"),
          py::arg("search_path"), py::arg("mode"));
    m.def("render", &render_py, py::arg("scene"), py::arg("spp"), py::arg("seed"),
          py::arg("sensor"), py::arg("threads"), py::arg("crop"), py::arg("pass_index"),
          py::arg("pass_count"), py::arg("progress"), py::arg("mode"));
    m.def("write", &write_py, py::arg("pixels"), py::arg("channels"), py::arg("path"),
          py::arg("half"), py::arg("metadata"), py::arg("ocio_config"), py::arg("display"),
          py::arg("view"), py::arg("looks"), py::arg("window"));
    m.def("read", &read_py, py::arg("path"));
    m.def("scene_info",
          [](const std::string &path, const std::map<std::string, std::string> &params,
             bool lenient, const std::vector<std::string> &search_path,
             const std::optional<std::string> &mode) {
              if (!fs::exists(path)) FACET_THROW("scene file \"{}\" does not exist", path);
              SceneInfo info;
              const LoadOptions opts = load_options(params, lenient, search_path, mode);
              {
                  py::gil_scoped_release release;
                  info = scene_info(path, opts);
              }
              py::list sensors;
              for (const auto &s : info.sensors)
                  sensors.append(py::dict(py::arg("plugin") = s.plugin, py::arg("film") = s.film,
                                          py::arg("sampler") = s.sampler,
                                          py::arg("film_size") = py::make_tuple(s.width, s.height),
                                          py::arg("spp") = s.spp));
              return py::dict(py::arg("sensors") = sensors, py::arg("integrator") = info.integrator,
                              py::arg("plugins") = info.plugins, py::arg("mode") = opts.mode);
          });
    m.def("merge", &merge_py, py::arg("parts"));
    m.def("modes", &modes);
    m.def("plugins", &plugins_py);
    m.def("add_plugin_dir", [](const std::string &dir) {
        PluginRegistry::instance().add_search_dir(checked_path(dir, "add_plugin_dir"));
    });
    m.def("plugin_search_path", []() { return PluginRegistry::instance().search_path(); });
    m.def("set_log_level", [](const std::string &level) {
        static const std::map<std::string, LogLevel> levels = {
            {"trace", LogLevel::Trace}, {"debug", LogLevel::Debug}, {"info", LogLevel::Info},
            {"warn", LogLevel::Warn},   {"error", LogLevel::Error}, {"off", LogLevel::Off}};
        auto it = levels.find(level);
        if (it == levels.end())
            FACET_THROW("log level \"{}\": expected trace, debug, info, warn, error or off", level);
        Logger::set_level(it->second);
    });

    py::class_<Chi2Result>(m, "Chi2Result", "What facet.chi2 found")
        .def_readonly("passed", &Chi2Result::passed)
        .def_readonly("statistic", &Chi2Result::statistic)
        .def_readonly("dof", &Chi2Result::dof)
        .def_readonly("p_value", &Chi2Result::p_value)
        .def_readonly("significance", &Chi2Result::significance)
        .def_readonly("failures", &Chi2Result::failures)
        .def_readonly("notes", &Chi2Result::notes)
        .def_readonly("samples", &Chi2Result::samples)
        .def_readonly("pdf_integral", &Chi2Result::pdf_integral)
        .def_readonly("description", &Chi2Result::description)
        .def_property_readonly(
            "observed",
            [](const Chi2Result &r) { return histogram(r.observed, r.cos_res, r.phi_res); },
            "Counts per cell: rows are cos theta from -1 to 1, columns phi from -pi to pi")
        .def_property_readonly(
            "expected",
            [](const Chi2Result &r) { return histogram(r.expected, r.cos_res, r.phi_res); },
            "Expected counts, laid out like `observed`")
        .def_property_readonly("mean_weight",
                               [](const Chi2Result &r) {
                                   return py::make_tuple(r.mean_weight.r, r.mean_weight.g,
                                                         r.mean_weight.b);
                               })
        .def("summary", &Chi2Result::summary)
        .def("__repr__", [](const Chi2Result &r) {
            return fmt::format("<facet.Chi2Result {} statistic={:.6g} dof={} p_value={:.6g}>",
                               r.passed ? "passed" : "REJECTED", r.statistic, r.dof, r.p_value);
        });

    m.def("chi2_object_xml", [](const std::string &kind, const std::string &plugin,
                                const std::vector<std::string> &entries) {
        ObjectType t = object_type_from_name(kind);
        if (t == ObjectType::Unknown) FACET_THROW("unknown object kind \"{}\"", kind);
        return chi2_object_xml(t, plugin, entries);
    });
    m.def("chi2_emitter_scene_xml", &EmitterAdapter::scene_xml);
    m.def("chi2_bsdf",
          [](const std::string &xml, const std::vector<float> &wi, const std::string &mode,
             int component, const py::dict &o, const std::optional<std::string> &colour_mode) {
              BSDFContext ctx;
              if (mode == "importance")
                  ctx.mode = TransportMode::Importance;
              else if (mode != "radiance")
                  FACET_THROW("mode \"{}\": expected radiance or importance", mode);
              if (component >= 0) ctx.component = uint32_t(component);
              Chi2Options opts = chi2_options(o);
              const std::string colour = colour_mode ? resolve_mode(*colour_mode) : default_mode();
              std::unique_ptr<BSDFAdapter> adapter;
              {
                  py::gil_scoped_release release;
                  adapter = std::make_unique<BSDFAdapter>(xml, vec3(wi, "wi"), ctx, colour);
              }
              return run_adapter(*adapter, opts);
          });
    m.def("chi2_emitter", [](const std::string &scene_xml, const std::vector<float> &ref,
                             bool emission, const py::dict &o,
                             const std::optional<std::string> &colour_mode) {
        Chi2Options opts = chi2_options(o);
        const std::string colour = colour_mode ? resolve_mode(*colour_mode) : default_mode();
        if (emission) {
            std::unique_ptr<EmissionAdapter> adapter;
            {
                py::gil_scoped_release release;
                adapter = std::make_unique<EmissionAdapter>(scene_xml, 0, colour);
            }
            return run_adapter(*adapter, opts);
        }
        Vector3f r = vec3(ref, "ref");
        std::unique_ptr<EmitterAdapter> adapter;
        {
            py::gil_scoped_release release;
            adapter =
                std::make_unique<EmitterAdapter>(scene_xml, Point3f(r.x, r.y, r.z), 0, colour);
        }
        return run_adapter(*adapter, opts);
    });
    m.def("chi2_microfacet", [](const std::string &type, float alpha_u, float alpha_v, bool visible,
                                const std::vector<float> &wi, const py::dict &o) {
        Chi2Options opts = chi2_options(o);
        MicrofacetAdapter adapter(type, alpha_u, alpha_v, visible, vec3(wi, "wi"));
        return run_adapter(adapter, opts);
    });
    m.def("direction_from_angles", [](float theta, float phi) {
        Vector3f d = direction_from_angles(theta, phi);
        return std::vector<float>{d.x, d.y, d.z};
    });
}
