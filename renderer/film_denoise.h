// A film's denoised image (denoiser.h), and the estimate of its noise: the difference between the
// denoised images of the film's two parts of samples (the raw error estimate's halves,
// halves_error_estimate), which measures the denoised image's variance and not its bias.
#pragma once

#include <cmath>
#include <string>

#include "denoiser.h"
#include "film.h"

namespace pt {

struct DenoisedFilm {
  bool ok = false;
  ImageRGB image;            // the denoised mean (when ok)
  double seconds = 0;        // denoising the image
  // Relative MSE of the image's noise from its denoised halves (infinite where not asked for or not
  // yet possible), and the time it took.
  double noise = INFINITY, noise_seconds = 0;
  std::string error;         // why not ok
};

// Denoises the film's image with its features (Film::has_features; otherwise an error). With
// `estimate`, also its two parts, for `noise`. Never throws.
DenoisedFilm denoise_film(const Film& film, DenoiseQuality quality, int threads, bool estimate);

// The noise estimate from the denoised images of the two parts and the denoised whole, with each
// pixel's weight p (n - p) / n^2 (Film::part_weights): the mean over pixels of
// weight (L(first) - L(rest))^2 / (L(whole)^2 + eps), on luminance.
double denoised_noise(const ImageRGB& first, const ImageRGB& rest, const ImageRGB& whole, const std::vector<float>& weights);

}  // namespace pt
