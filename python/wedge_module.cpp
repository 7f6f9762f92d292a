// The `wedge` Python module: the library's scene loader, render(), image writers and metrics over
// numpy arrays, with no logic of its own. Keywords of render() are the command line's flags
// (apps/wedge/render_flags.h) with underscores, parsed by the same CLI11 flags, so that every
// option, check and error message is the CLI's; errors raise wedge.Error (a ValueError) with the
// message `wedge` prints. A render runs on a thread of its own without the GIL while the calling
// thread polls for signals, so Ctrl-C cancels it (core/cancel.h) and raises KeyboardInterrupt.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <future>
#include <optional>
#include <thread>

#include "apps/wedge/common.h"
#include "apps/wedge/render_flags.h"
#include "core/cancel.h"
#include "core/error.h"
#include "core/parallel.h"
#include "io/image_io.h"
#include "metrics/metrics.h"
#include "render/output.h"
#include "scene/scene.h"
#include "scene/scene_loader.h"

namespace py = pybind11;

namespace wedge::python {

namespace {

/// A loaded scene description, built into an Embree scene per render (the CLI does the same).
struct Scene {
    std::string name;  // as the user gave it: a built-in name, a path, or "<dict>"
    scene::SceneDesc desc;
};

struct Result {
    std::string scene;
    render::RenderResult result;
};

/// A keyword as the flag it stands for: max_extra_spp=32 -> "--max-extra-spp=32", True/False ->
/// "=on"/"=off" (CLI11 reads both for flags and negated flags, and they are the values of on/off
/// options such as --layers), resolution=(W, H) -> "WxH".
std::string keywordFlag(const std::string& key, const py::handle& value) {
    std::string flag = "--" + key;
    std::replace(flag.begin(), flag.end(), '_', '-');
    std::string text;
    if (py::isinstance<py::bool_>(value))
        text = value.cast<bool>() ? "on" : "off";
    else if (key == "resolution" && (py::isinstance<py::tuple>(value) || py::isinstance<py::list>(value))) {
        py::sequence wh = value.cast<py::sequence>();
        if (wh.size() != 2) throw Error("--resolution " + std::string(py::str(value)), "expected (W, H)");
        text = std::string(py::str(wh[0])) + "x" + std::string(py::str(wh[1]));
    } else
        text = py::str(value);
    return flag + "=" + text;
}

/// The keywords, checked and mapped by the command line's flags (CLI11's messages on error).
app::RenderFlags parseKeywords(const py::kwargs& kwargs) {
    CLI::App parser("wedge.render");
    parser.set_help_flag();  // no -h/--help among the keywords
    app::RenderFlags flags;
    app::addRenderFlags(parser, flags);
    std::vector<std::string> args;
    for (const auto& [key, value] : kwargs)
        if (!value.is_none()) args.push_back(keywordFlag(py::str(key), value));
    std::reverse(args.begin(), args.end());  // CLI11 takes the vector last argument first
    parser.parse(args);
    return flags;
}

/// Runs `work` on a thread of its own without the GIL. The caller's thread checks for signals
/// every 50 ms: on Ctrl-C it cancels the render, waits for it to stop and raises KeyboardInterrupt.
template <class Work>
auto runInterruptibly(Work&& work) -> decltype(work()) {
    using T = decltype(work());
    std::packaged_task<T()> task(std::forward<Work>(work));
    std::future<T> done = task.get_future();
    clearCancel();
    bool interrupted = false;
    {
        py::gil_scoped_release release;
        std::thread worker(std::move(task));
        while (done.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
            py::gil_scoped_acquire gil;
            if (PyErr_CheckSignals() != 0) {  // the handler raised (KeyboardInterrupt)
                interrupted = true;
                requestCancel();
                break;
            }
        }
        worker.join();
    }
    clearCancel();
    if (interrupted) throw py::error_already_set();
    return done.get();  // the render's own exception, if any
}

/// A read-only array over memory that `owner` keeps alive.
py::array view(const py::object& owner, std::vector<py::ssize_t> shape, std::vector<py::ssize_t> strides,
               const float* data) {
    py::array a(py::dtype::of<float>(), std::move(shape), std::move(strides), data, owner);
    py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
    return a;
}

Image3f imageFromArray(const py::array_t<float, py::array::c_style | py::array::forcecast>& a,
                       const std::string& name) {
    if (a.ndim() != 3 || a.shape(2) != 3 || a.shape(0) < 1 || a.shape(1) < 1) {
        std::string shape;
        for (py::ssize_t i = 0; i < a.ndim(); ++i) shape += (i ? ", " : "") + std::to_string(a.shape(i));
        throw Error(name, "expected a float array of shape (H, W, 3), got (" + shape + ")");
    }
    Image3f img(int(a.shape(1)), int(a.shape(0)));
    std::copy(a.data(), a.data() + a.size(), &img[0].x);
    return img;
}

bool isPath(const py::handle& x) { return py::isinstance<py::str>(x) || py::hasattr(x, "__fspath__"); }
std::string pathOf(const py::handle& x) { return py::str(py::module_::import("os").attr("fspath")(x)); }

/// compare()'s arguments: a Result, a path (read as `wedge compare` reads it) or an (H, W, 3)
/// array; errors name the path, else `name`.
Image3f imageArgument(const py::handle& x, const std::string& name) {
    if (py::isinstance<Result>(x)) return x.cast<const Result&>().result.color;
    if (isPath(x)) return io::readColor(pathOf(x));
    return imageFromArray(py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(x), name);
}

py::object jsonToPython(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

Scene loadScene(const py::object& source) {
    Scene s;
    if (py::isinstance<py::dict>(source)) {
        s.name = "<dict>";
        std::string text = py::module_::import("json").attr("dumps")(source).cast<std::string>();
        s.desc = scene::parseScene(text, s.name, std::filesystem::current_path().string());
    } else if (isPath(source)) {
        s.name = pathOf(source);
        s.desc = scene::loadScene(s.name);
    } else {
        throw py::type_error("load_scene() takes a built-in scene name, a path or a dict");
    }
    // What the CLI prints as "wedge: warning: ...", as Python warnings.
    for (const auto& w : s.desc.warnings) PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1);
    return s;
}

Result renderScene(const Scene& s, const py::kwargs& kwargs) {
    const app::RenderFlags flags = parseKeywords(kwargs);
    const render::RenderOptions options = flags.renderOptions();
    scene::SceneDesc desc = s.desc;
    flags.applyTo(desc);
    Result r;
    r.scene = s.name;
    r.result = runInterruptibly([&] {
        ThreadLimit limit(flags.threads);
        scene::Scene built(std::move(desc));
        return render::render(built, options);
    });
    // What `wedge render` prints as a warning after the render, as a Python warning.
    if (const std::string unlit = render::unlitWarning(s.desc, r.result); !unlit.empty())
        if (PyErr_WarnEx(PyExc_UserWarning, (s.name + ": " + unlit).c_str(), 1) < 0) throw py::error_already_set();
    return r;
}

}  // namespace

}  // namespace wedge::python

PYBIND11_MODULE(wedge, m) {
    using namespace wedge;
    using namespace wedge::python;
    m.doc() = "wedge: sparse sampling and Fourier-derived reconstruction filters for distribution effects.\n\n"
              "load_scene() a built-in scene, a JSON file or a dict; render() it with a method (mc, aaf, maaf, "
              "atrous); look at .color, .buffers and .stats as numpy arrays and dicts; write_image() and "
              "compare() as `wedge render -o` and `wedge compare` do.";

    static py::exception<Error> error(m, "Error", PyExc_ValueError);
    error.doc() = "Bad input (a scene, an option, an image): the message `wedge` prints, naming the file or flag.";
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const Error& e) {
            PyErr_SetString(error.ptr(), e.what());
        } catch (const CLI::ParseError& e) {
            PyErr_SetString(error.ptr(), e.what());
        }
    });

    py::class_<Scene>(m, "Scene", "A loaded scene description (load_scene()); rendered by render().")
        .def_readonly("name", &Scene::name, "The name or path it was loaded from, or '<dict>'.")
        .def_property_readonly(
            "resolution", [](const Scene& s) { return py::make_tuple(s.desc.camera.width, s.desc.camera.height); },
            "(W, H) of the scene's camera.")
        .def_property_readonly(
            "warnings", [](const Scene& s) { return s.desc.warnings; },
            "What the scene asks for that wedge does not render (`wedge render` prints them as warnings).")
        .def("__repr__", [](const Scene& s) {
            return "<wedge.Scene '" + s.name + "' " + std::to_string(s.desc.camera.width) + "x" +
                   std::to_string(s.desc.camera.height) + ">";
        });
    py::class_<Result>(m, "Result", "What render() returns: the image, its buffers and its statistics.")
        .def_property_readonly(
            "color",
            [](const py::object& self) {
                const Image3f& c = self.cast<const Result&>().result.color;
                const py::ssize_t w = c.width(), f = sizeof(float);
                return view(self, {c.height(), w, 3}, {w * 3 * f, 3 * f, f}, &c[0].x);
            },
            "Linear radiance, a read-only float32 array of shape (H, W, 3).")
        .def_property_readonly(
            "buffers",
            [](const py::object& self) {
                const render::RenderResult& r = self.cast<const Result&>().result;
                const py::ssize_t w = r.color.width(), h = r.color.height(), f = sizeof(float);
                py::dict planes;
                for (const io::ExrChannel& c : render::exrChannels(r))
                    if (c.name != "R" && c.name != "G" && c.name != "B")
                        planes[py::str(c.name)] = view(self, {h, w}, {w * c.stride * f, c.stride * f}, c.data);
                return planes;
            },
            "The render's named buffers as `wedge render -o x.exr` writes them besides R, G, B: a dict of "
            "read-only float32 arrays of shape (H, W) ('depth', 'spp', 'normal.X', ...).")
        .def_property_readonly(
            "stats",
            [](const Result& r) { return jsonToPython(render::statsJson(r.result, r.scene)); },
            "Timings and counts: a dict with the keys of `wedge render --stats`.")
        .def("__repr__", [](const Result& r) {
            return "<wedge.Result " + r.result.method + " " + std::to_string(r.result.color.width()) + "x" +
                   std::to_string(r.result.color.height()) + ">";
        });

    m.def("scenes", [] {
        std::vector<std::string> names;
        for (const auto& s : scene::builtinScenes()) names.push_back(s.name);
        return names;
    }, "The built-in scenes' names (`wedge scenes`).");

    m.def("load_scene", &loadScene, py::arg("source"),
          "Loads a scene: a built-in name (see scenes()), a path to a scene file (JSON), or a dict with the "
          "file's structure (relative mesh paths then resolve against the current directory). What the scene "
          "asks for that wedge does not render comes as UserWarning.");

    m.def("render", &renderScene, py::arg("scene"),
          "render(scene, method='mc', spp=None, seed=None, resolution=None, threads=0, **options) -> Result\n\n"
          "Renders a Scene as `wedge render` does. Every keyword is optional and is one of `wedge render`'s "
          "flags with underscores for dashes: method ('mc', 'aaf', 'maaf', 'atrous'), spp, seed, resolution "
          "((W, H) or 'WxH'), threads (0: all cores), quiet, aov, max_extra_spp, maaf_components, "
          "maaf_paper_rates, no_focal_fallback, sampler, ... (`wedge render --help` lists them all); None keeps the "
          "default. The same scene, method, seed and resolution give the CLI's image bit for bit, whatever "
          "the thread count. The GIL is released while rendering; Ctrl-C stops the render with "
          "KeyboardInterrupt. Raises wedge.Error with the CLI's message on bad input.");

    m.def("write_image", [](const std::string& path, const Result& r) {
        io::checkOutputPath(path, render::outputExtensions());
        render::writeOutput(r.result, path);
    }, py::arg("path"), py::arg("result"),
          "Writes a Result as `wedge render -o PATH` does: .exr with every buffer as named channels, .png "
          "tone-mapped sRGB, .pfm colour.");
    m.def("write_image", [](const std::string& path, const py::array& image) {
        io::checkOutputPath(path, render::outputExtensions());
        io::writeColor(path, imageFromArray(py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(image), path));
    }, py::arg("path"), py::arg("image"), "Writes a linear (H, W, 3) float array as .exr (R, G, B), .png or .pfm.");

    m.def("read_image", [](const py::object& path) {
        const std::string name = pathOf(path);
        Image3f img;
        {
            py::gil_scoped_release release;
            img = io::readColor(name);
        }
        py::array_t<float> a({py::ssize_t(img.height()), py::ssize_t(img.width()), py::ssize_t(3)});
        std::copy(&img[0].x, &img[0].x + 3 * img.size(), a.mutable_data());
        return a;
    }, py::arg("path"),
          "Reads an image as `wedge compare` reads it (.exr: its R, G, B; .png: sRGB decoded to linear; .pfm) "
          "into a linear float32 array of shape (H, W, 3). Raises wedge.Error naming the file on bad input.");
    m.def("read_buffers", [](const py::object& path) {
        const std::string name = pathOf(path);
        if (io::extension(name) != ".exr")
            throw Error(name, "read_buffers() needs an EXR (written by `wedge render -o x.exr` or write_image())");
        io::ExrImage exr;
        {
            py::gil_scoped_release release;
            exr = io::readExr(name);
        }
        py::dict planes;
        for (const auto& [channel, values] : exr.channels) {
            if (channel == "R" || channel == "G" || channel == "B") continue;
            py::array_t<float> a({py::ssize_t(exr.height), py::ssize_t(exr.width)});
            std::copy(values.begin(), values.end(), a.mutable_data());
            planes[py::str(channel)] = a;
        }
        return planes;
    }, py::arg("path"),
          "Reads an EXR's named buffers besides R, G, B (as Result.buffers has them: 'depth', 'spp', "
          "'normal.X', ...) into a dict of float32 arrays of shape (H, W).");

    m.def("compare", [](const py::object& test, const py::object& reference, const py::object& varianceFrom,
                        const py::object& noiseFrom) {
        auto nameOf = [](const py::object& x, const char* fallback) { return isPath(x) ? pathOf(x) : std::string(fallback); };
        const std::string testName = nameOf(test, "test"), refName = nameOf(reference, "reference");
        const Image3f a = imageArgument(test, testName), b = imageArgument(reference, refName);
        metrics::checkComparable(a, testName, b, refName);
        // As `wedge compare --variance-from OTHER --reference-noise-from REF2`: OTHER is TEST made
        // with another seed, REF2 the reference made with another seed.
        std::optional<Image3f> other, second;
        if (!varianceFrom.is_none()) {
            const std::string name = nameOf(varianceFrom, "variance_from");
            other = imageArgument(varianceFrom, name);
            app::checkSecondImage(*other, name, "--variance-from", a, testName);
        }
        if (!noiseFrom.is_none()) {
            const std::string name = nameOf(noiseFrom, "reference_noise_from");
            second = imageArgument(noiseFrom, name);
            app::checkSecondImage(*second, name, "--reference-noise-from", b, refName);
        }
        metrics::Metrics mm;
        std::optional<double> variance, noise;
        {
            py::gil_scoped_release release;
            mm = metrics::compare(a, b);
            if (other) variance = metrics::seedVariance(a, *other, b);
            if (second) noise = metrics::seedVariance(b, *second, b);
        }
        return jsonToPython(app::metricsJson(mm, variance, noise));  // psnr None for identical images
    }, py::arg("test"), py::arg("reference"), py::kw_only(), py::arg("variance_from") = py::none(),
          py::arg("reference_noise_from") = py::none(),
          "The metrics `wedge compare --json` prints of TEST against REFERENCE, each a Result, a path or a "
          "linear (H, W, 3) array: a dict with relmse (eps 0.01, no 0.5 factor), smape, psnr (dB, tone-mapped; "
          "None for identical images) and ssim (tone-mapped). variance_from (TEST made with another seed) adds "
          "variance and bias2_and_reference_noise; reference_noise_from (REFERENCE made with another seed) adds "
          "reference_noise and relmse_net, and with both, bias2.");
}
