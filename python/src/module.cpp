// The Python module's native part, wavetrace._wavetrace (docs/python.md): the scene
// readers, a render session (app/session.hpp) and the image writers, with the
// command's settings table and messages. python/wavetrace/__init__.py wraps it.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/function.h>
#include <nanobind/stl/map.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/job.hpp"
#include "app/session.hpp"
#include "cpu/parallel.hpp"
#include "cuda/cuda_backend.hpp"
#include "device/device.hpp"
#include "errors/errors.hpp"
#include "image/image_io.hpp"
#include "render/settings.hpp"
#include "scene/scene_file.hpp"

namespace nb = nanobind;
using nlohmann::json;

namespace {

// A Python value as JSON: dicts (string keys), lists and tuples, str, bool, int,
// float, None, and numpy's arrays and scalars (through tolist() and item()).
json to_json(nb::handle h) {
  if (h.is_none()) return nullptr;
  if (nb::isinstance<nb::bool_>(h)) return nb::cast<bool>(h);
  if (nb::isinstance<nb::int_>(h)) return nb::cast<int64_t>(h);
  if (nb::isinstance<nb::float_>(h)) return nb::cast<double>(h);
  if (nb::isinstance<nb::str>(h)) return nb::cast<std::string>(h);
  if (nb::isinstance<nb::dict>(h)) {
    json out = json::object();
    for (auto [key, value] : nb::borrow<nb::dict>(h)) {
      if (!nb::isinstance<nb::str>(key)) {
        throw wt::InputError("scene dict: a key must be a string (got " + nb::cast<std::string>(nb::repr(key)) + ")");
      }
      out[nb::cast<std::string>(key)] = to_json(value);
    }
    return out;
  }
  if (nb::isinstance<nb::list>(h) || nb::isinstance<nb::tuple>(h)) {
    json out = json::array();
    for (nb::handle item : h) out.push_back(to_json(item));
    return out;
  }
  if (nb::hasattr(h, "tolist")) return to_json(h.attr("tolist")());  // a numpy array or scalar
  throw wt::InputError("scene dict: " + nb::cast<std::string>(nb::repr(nb::type_name(h.type()))) +
                       " is not a JSON value (dict, list, str, number, bool, None or a numpy array)");
}

// The keyword arguments of a render as a job: each setting of the settings table by
// its key, and backend, kernel and devices, checked as the command checks them.
wt::app::Job job_from(const nb::kwargs& kwargs) {
  wt::app::Job job;
  job.progress = false;
  for (auto [k, v] : kwargs) {
    const std::string key = nb::cast<std::string>(k);
    if (key == "backend" || key == "kernel") {
      if (!nb::isinstance<nb::str>(v)) throw wt::InputError(key + ": must be a string");
      (key == "backend" ? job.backend : job.kernel) = nb::cast<std::string>(v);
      continue;
    }
    if (key == "aovs") {
      if (nb::isinstance<nb::str>(v)) {
        job.aov = nb::cast<std::string>(v);
      } else {
        for (nb::handle a : v) job.aov += (job.aov.empty() ? "" : ",") + nb::cast<std::string>(a);
      }
      wt::parse_aovs(job.aov, "aovs");  // the names checked with this field's name
      continue;
    }
    if (key == "denoise") {
      if (!nb::isinstance<nb::bool_>(v)) throw wt::InputError("denoise: must be True or False");
      job.denoise = nb::cast<bool>(v);
      continue;
    }
    if (key == "denoise_quality") {
      const std::string q = nb::isinstance<nb::str>(v) ? nb::cast<std::string>(v) : "";
      if (q != "high" && q != "balanced") throw wt::InputError("denoise_quality: must be 'high' or 'balanced'");
      job.denoise_quality = q;
      continue;
    }
    if (key == "devices") {
      if (nb::isinstance<nb::str>(v)) {
        job.devices = nb::cast<std::string>(v);
      } else {
        std::string list;
        for (nb::handle d : v) list += (list.empty() ? "" : ",") + std::to_string(nb::cast<int64_t>(d));
        job.devices = list;
      }
      continue;
    }
    const wt::Setting* found = nullptr;
    for (const wt::Setting& s : wt::settings()) {
      if (key == s.key) found = &s;
    }
    if (found != nullptr && found->id == wt::SettingId::CheckpointEvery) {
      throw wt::InputError(key + ": a render in memory keeps no checkpoint (the command's --checkpoint does)");
    }
    if (found == nullptr) {
      std::string known = "backend, kernel, devices, aovs, denoise, denoise_quality";
      for (const wt::Setting& s : wt::settings()) {
        if (s.id != wt::SettingId::CheckpointEvery) known += std::string(", ") + s.key;
      }
      throw wt::InputError("render: unknown setting '" + key + "' (known: " + known + ")");
    }
    if (found->type == wt::SettingType::Real) {
      const double x = nb::cast<double>(v);
      wt::check_real_setting(found->id, x);
      job.noise_threshold = x;
    } else {
      if (nb::isinstance<nb::float_>(v) || nb::isinstance<nb::bool_>(v)) {
        throw wt::InputError(key + ": must be an integer (got " + nb::cast<std::string>(nb::repr(v)) + ")");
      }
      const int64_t x = nb::cast<int64_t>(v);
      wt::check_setting(found->id, x);
      wt::app::set_setting(job, found->id, x);
    }
  }
  return job;
}

// A scene loaded once, rendered as often as asked.
struct PyScene {
  std::shared_ptr<wt::app::Session> session;
};

PyScene make_scene(wt::Scene scene, const std::string& source) {
  return PyScene{std::make_shared<wt::app::Session>(std::make_shared<const wt::Scene>(std::move(scene)), source)};
}

// `data`'s (H, W, C) floats as an array where they lie, kept alive by the array: in
// host memory (cuda_device < 0), a numpy array; in the memory of CUDA device
// `cuda_device`, an array that hands itself over by DLPack (torch.from_dlpack,
// cupy.from_dlpack read it where it lies).
nb::object array_of(std::shared_ptr<float> data, size_t height, size_t width, size_t channels, int cuda_device) {
  float* at = data.get();
  auto* kept = new std::shared_ptr<float>(std::move(data));
  nb::capsule owner(kept, [](void* p) noexcept { delete static_cast<std::shared_ptr<float>*>(p); });
  if (cuda_device < 0) return nb::cast(nb::ndarray<nb::numpy, float>(at, {height, width, channels}, owner));
  return nb::cast(nb::ndarray<nb::array_api, float, nb::device::cuda>(
      at, {height, width, channels}, owner, {}, nb::dtype<float>(), nb::device::cuda::value, cuda_device));
}

// Host values as an array on CUDA device `cuda_device` (copied there), or on the host
// where it is below 0.
nb::object image_array(std::shared_ptr<float> host, size_t height, size_t width, size_t channels, int cuda_device) {
  if (cuda_device < 0) return array_of(std::move(host), height, width, channels, -1);
  float* on_device = wt::cuda::copy_to_device(host.get(), height * width * channels, cuda_device);
  return array_of(std::shared_ptr<float>(on_device, [](float* p) { wt::cuda::free_on_device(p); }), height, width,
                  channels, cuda_device);
}

nb::object image_array(std::vector<float> values, size_t height, size_t width, size_t channels, int cuda_device) {
  auto owned = std::make_shared<std::vector<float>>(std::move(values));
  return image_array(std::shared_ptr<float>(owned, owned->data()), height, width, channels, cuda_device);
}

// Pixels of 3 floats as an (H, W, 4) image, alpha 1, written over the host's
// threads into memory nothing clears first (a 1080p image is 8 M floats, a share of
// a short render).
nb::object rgba_array(const std::vector<float>& rgb, size_t height, size_t width, int cuda_device) {
  const int64_t pixels = static_cast<int64_t>(rgb.size() / 3);
  std::shared_ptr<float> out(new float[static_cast<size_t>(pixels) * 4], std::default_delete<float[]>());
  const float* in = rgb.data();
  float* to = out.get();
  wt::cpu::parallel_for(pixels, int64_t(1) << 16, wt::cpu::thread_count(0), [in, to](int64_t begin, int64_t end, int) {
    for (int64_t i = begin; i < end; ++i) {
      to[4 * i] = in[3 * i];
      to[4 * i + 1] = in[3 * i + 1];
      to[4 * i + 2] = in[3 * i + 2];
      to[4 * i + 3] = 1.0f;
    }
  });
  return image_array(std::move(out), height, width, 4, cuda_device);
}

// The page-locked memory that images finished on a device are brought back to, kept
// from one render to the next (cuda/device_image.hpp).
wt::cuda::ImageBlocks& pinned_images() {
  static wt::cuda::ImageBlocks images(wt::cuda::ImageBlocks::Memory::PageLocked, 2);
  return images;
}

// Renders with the GIL released; the progress callback and Ctrl-C are looked at,
// with it held, wherever the render tells its progress, at most every 10 ms
// (app/session.hpp). A Python exception (KeyboardInterrupt, or one the callback
// raised) stops the render there and is raised once it has returned.
nb::tuple render(const PyScene& scene, const nb::object& progress, const std::string& device, const nb::kwargs& kwargs) {
  if (device != "cpu" && device != "cuda") throw wt::InputError("device: must be 'cpu' or 'cuda' (got '" + device + "')");
  const wt::app::Job job = job_from(kwargs);
  if (device == "cuda" && wt::cuda::device_count() == 0) {
    throw wt::DeviceError("device: cuda was asked for the image, but no CUDA device is present");
  }
  std::optional<nb::python_error> pending;
  std::function<void(double)> on_progress;
  if (!progress.is_none()) {
    on_progress = [&](double done) {
      nb::gil_scoped_acquire held;
      if (pending) return;
      try {
        progress(done);
      } catch (nb::python_error& e) {
        pending.emplace(std::move(e));
      }
    };
  }
  const auto stop = [&]() {
    nb::gil_scoped_acquire held;
    if (!pending && PyErr_CheckSignals() != 0) pending.emplace();  // takes the raised KeyboardInterrupt
    return pending.has_value();
  };
  wt::app::SessionRender done;
  // An image finished on its CUDA device (a render with no AOV and no denoiser) is
  // handed over there (device "cuda"), or written by the device straight into
  // page-locked host memory (device "cpu"), which is then the numpy array's.
  wt::cuda::ImageMemory memory;
  if (device == "cpu") memory = [](size_t floats) { return pinned_images().take(floats); };
  {
    nb::gil_scoped_release released;
    done = scene.session->render(job, on_progress, stop, memory);
  }
  if (pending) throw std::move(*pending);
  const wt::app::JobOutcome& out = done.outcome;
  const wt::RenderParams& p = out.params;
  const size_t h = p.height, w = p.width;
  // The stats as Python's json reads them, while an image finished on the device
  // may still be crossing the bus (cuda/device_image.hpp); then the wait for it.
  const nb::object stats = nb::module_::import_("json").attr("loads")(scene.session->stats(job, out).dump());
  if (done.image.rgba) {
    {
      nb::gil_scoped_release released;
      done.image.wait();
    }
    return nb::make_tuple(array_of(std::move(done.image.rgba), h, w, 4, device == "cpu" ? -1 : done.image.device),
                          stats, nb::dict(), nb::none());
  }
  const int on = device == "cuda" ? done.cuda_device : -1;
  nb::dict aovs;
  for (wt::AovImage& a : done.aovs) {
    const size_t c = a.channels.size();
    aovs[a.name.c_str()] = image_array(std::move(a.values), h, w, c, on);
  }
  // A denoised render's image is the denoiser's; the render itself its noisy image.
  nb::object noisy = nb::none();
  nb::object image;
  if (job.denoise) {
    image = rgba_array(done.denoised, h, w, on);
    noisy = rgba_array(out.result.rgb, h, w, on);
  } else {
    image = rgba_array(out.result.rgb, h, w, on);
  }
  return nb::make_tuple(image, stats, aovs, noisy);
}

void write_image(nb::ndarray<const float, nb::ndim<3>, nb::c_contig, nb::device::cpu> image, const std::string& path,
                 const std::string& encoding) {
  const size_t h = image.shape(0), w = image.shape(1), c = image.shape(2);
  if (c != 3 && c != 4) throw wt::InputError("write_image: an image of 3 or 4 channels (got " + std::to_string(c) + ")");
  if (encoding != "srgb" && encoding != "gamma2") throw wt::InputError("write_image: encoding must be srgb or gamma2");
  wt::check_output_path(path);
  std::vector<float> rgb(h * w * 3);
  for (size_t i = 0; i < h * w; ++i) {
    for (size_t k = 0; k < 3; ++k) rgb[3 * i + k] = image.data()[c * i + k];
  }
  nb::gil_scoped_release released;
  wt::write_image(path, static_cast<int>(w), static_cast<int>(h), rgb,
                  encoding == "srgb" ? wt::Encoding::Srgb : wt::Encoding::Gamma2);
}

}  // namespace

NB_MODULE(_wavetrace, m) {
  m.doc() = "wavetrace's native part: use the package wavetrace (docs/python.md)";
  // Bad input (a scene, a setting, an output path) is a ValueError with the command's
  // one line; a failure of the machine, a RuntimeError naming the call and the stage.
  nb::register_exception_translator([](const std::exception_ptr& p, void*) {
    try {
      std::rethrow_exception(p);
    } catch (const wt::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const wt::OutputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const wt::DeviceError& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    }
  });
  nb::class_<PyScene>(m, "Scene", "A scene loaded once (load_scene, scene_from_dict), rendered as often as asked.")
      .def_prop_ro("source", [](const PyScene& s) { return s.session->source(); }, "The file it was read from.")
      .def_prop_ro(
          "uploads", [](const PyScene& s) { return s.session->uploads(); },
          "How many times the scene was uploaded to a device: once a device, at its first render there "
          "(and once more for each render that shares a device with another at the same time).")
      .def(
          "release_devices", [](const PyScene& s) { s.session->release_devices(); },
          "Frees the scene's copies on the devices; the next render there uploads it again.")
      .def_prop_ro(
          "warnings", [](const PyScene& s) { return s.session->scene().warnings; },
          "What the scene file holds that is not rendered as its author meant (a Mitsuba scene's mapping).");
  m.def(
      "load_scene",
      [](const std::string& path, const std::map<std::string, std::string>& defines) {
        return make_scene(wt::load_scene(path, defines), path);
      },
      nb::arg("path"), nb::arg("defines") = std::map<std::string, std::string>{},
      "A scene file: wavetrace's JSON, or a Mitsuba 3 .xml with its parameters (defines).");
  m.def(
      "scene_from_dict",
      [](const nb::dict& d, const std::string& source) {
        return make_scene(wt::scene_from_document(to_json(d), source), source);
      },
      nb::arg("d"), nb::arg("source") = "scene.json",
      "A scene in the JSON format's structure; relative paths are read from source's folder.");
  m.def("render", &render, nb::arg("scene"), nb::arg("progress") = nb::none(), nb::arg("device") = "cpu",
        nb::arg("kwargs"),
        "Renders the scene; returns (the (H, W, 4) float32 image, the stats as a dict (--stats's JSON), the AOVs by name, "
        "the noisy image of a denoised render or None), the arrays in host memory (device 'cpu') or on the "
        "render's CUDA device ('cuda').");
  m.def("kernels", [](const std::string& backend) { return wt::kernel_names(wt::app::parse_backend(backend)); },
        nb::arg("backend") = "cpu", "The kernels a backend runs.");
  m.def("cuda_device_count", [] { return wt::cuda::device_count(); }, "CUDA devices present.");
  m.def(
      "to_host",
      [](nb::ndarray<const float, nb::device::cuda, nb::c_contig> a) {
        std::vector<float> values(a.size());
        wt::cuda::copy_to_host(a.data(), a.size(), values.data());
        std::vector<size_t> shape;
        for (size_t i = 0; i < a.ndim(); ++i) shape.push_back(a.shape(i));
        auto* owned = new std::vector<float>(std::move(values));
        nb::capsule owner(owned, [](void* p) noexcept { delete static_cast<std::vector<float>*>(p); });
        return nb::ndarray<nb::numpy, float>(owned->data(), shape.size(), shape.data(), owner);
      },
      nb::arg("array"), "A float32 array in CUDA device memory, copied to a numpy array.");
  m.def(
      "pinned_allocations", [] { return pinned_images().allocations(); },
      "The blocks of page-locked host memory allocated so far for images brought back from a CUDA device (a "
      "block whose image is freed is kept for the next image of its size).");
  m.def("aov_names", [] { return wt::aov_names(); }, "The AOVs render(aovs=...) returns.");
  m.def("settings", [] {
    std::vector<std::string> keys;
    for (const wt::Setting& s : wt::settings()) {
      if (s.id != wt::SettingId::CheckpointEvery) keys.push_back(s.key);  // the command's files alone
    }
    return keys;
  }, "The keys of the settings table that render() takes.");
  m.def("write_image", &write_image, nb::arg("image"), nb::arg("path"), nb::arg("encoding") = "srgb",
        "Writes an (H, W, 3 or 4) float32 image: PNG (encoded), PFM or OpenEXR (linear), by extension.");
}
