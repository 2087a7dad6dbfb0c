// A film's denoised image and its noise estimate (film_denoise.h).
#include "film_denoise.h"

#include <chrono>
#include <exception>
#include <new>

namespace pt {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// What OIDN is documented to take: colour finite and not negative, albedo in [0, 1], normal in
// [-1, 1]. The film's guards keep its sums finite; this holds the ranges.
void clamp_inputs(ImageRGB& color, FilmFeatures& f) {
  auto clamp = [](float v, float lo, float hi) { return v > lo ? (v < hi ? v : hi) : lo; };  // NaN -> lo
  for (Vec3& c : color.pixels) c = Vec3(clamp(c.x, 0, 3.4e38f), clamp(c.y, 0, 3.4e38f), clamp(c.z, 0, 3.4e38f));
  for (Vec3& a : f.albedo.pixels) a = Vec3(clamp(a.x, 0, 1), clamp(a.y, 0, 1), clamp(a.z, 0, 1));
  for (Vec3& n : f.normal.pixels) n = Vec3(clamp(n.x, -1, 1), clamp(n.y, -1, 1), clamp(n.z, -1, 1));
}

}  // namespace

double denoised_noise(const ImageRGB& first, const ImageRGB& rest, const ImageRGB& whole, const std::vector<float>& weights) {
  const size_t n = whole.pixels.size();
  if (n == 0 || first.pixels.size() != n || rest.pixels.size() != n || weights.size() != n) return INFINITY;
  double sum = 0;
  for (size_t i = 0; i < n; ++i) {
    const double d = double(luminance(first.pixels[i])) - double(luminance(rest.pixels[i]));
    const double mu = luminance(whole.pixels[i]);
    sum += double(weights[i]) * d * d / (mu * mu + kRelMseEpsilon);
  }
  return sum / double(n);
}

DenoisedFilm denoise_film(const Film& film, DenoiseQuality quality, int threads, bool estimate) {
  DenoisedFilm out;
  try {
    if (!film.has_features()) {
      out.error = "the render has no denoising features";
      return out;
    }
    Denoiser& d = Denoiser::shared();
    const auto t0 = std::chrono::steady_clock::now();
    ImageRGB color = film.image();
    FilmFeatures f = film.features();
    clamp_inputs(color, f);
    if (!d.denoise(color, f.albedo, f.normal, quality, threads, out.image, out.error)) return out;
    for (size_t i = 0; i < out.image.pixels.size(); ++i)  // never a NaN out, whatever the library does
      if (!is_finite(out.image.pixels[i])) out.image.pixels[i] = color.pixels[i];
    out.seconds = seconds_since(t0);
    out.ok = true;
    if (!estimate) return out;
    const auto t1 = std::chrono::steady_clock::now();
    ImageRGB first, rest, first_d, rest_d;
    if (!film.part_images(first, rest)) return out;
    FilmFeatures unused = f;
    clamp_inputs(first, unused), clamp_inputs(rest, unused);
    std::string err;
    if (d.denoise(first, f.albedo, f.normal, quality, threads, first_d, err) &&
        d.denoise(rest, f.albedo, f.normal, quality, threads, rest_d, err))
      out.noise = denoised_noise(first_d, rest_d, out.image, film.part_weights());
    out.noise_seconds = seconds_since(t1);
  } catch (const std::bad_alloc&) {
    out.ok = false;
    out.error = "denoiser: out of memory";
  } catch (const std::exception& e) {
    out.ok = false;
    out.error = std::string("denoiser: ") + e.what();
  }
  return out;
}

}  // namespace pt
