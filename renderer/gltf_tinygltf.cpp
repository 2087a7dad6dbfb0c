// tinygltf's implementation and how it is run: file access only inside the scene's folder (it
// would also try the working directory and expand '~'), images decoded by OpenImageIO instead of
// its bundled stb_image, only the ones a material reads, within the texture limits.
#include <sys/stat.h>

#include <climits>
#include <cstdlib>
#include <fstream>  // before tinygltf: its writers use it even without its file system functions

#define TINYGLTF_IMPLEMENTATION
#include "gltf_reader.h"

#include "image.h"

namespace pt::gltf_detail {

namespace {

struct FsState {
  const Context* ctx;
  std::string folder;  // the scene's folder, resolved
  std::vector<std::string>* read;  // the files read, resolved
};

// The resolved path if `path` is a regular file inside the scene's folder, else "".
std::string inside_folder(const FsState& fs, const std::string& path) {
  char buf[PATH_MAX];
  if (fs.folder.empty() || !realpath(path.c_str(), buf)) return "";
  std::string real = buf;
  if (real.compare(0, fs.folder.size() + 1, fs.folder + "/") != 0) return "";
  struct stat st {};
  return stat(real.c_str(), &st) == 0 && S_ISREG(st.st_mode) ? real : "";
}

bool file_exists(const std::string& path, void* user) {
  return !inside_folder(*static_cast<FsState*>(user), path).empty();
}

std::string expand_path(const std::string& path, void*) { return path; }  // no '~', no variables

bool read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  const FsState& fs = *static_cast<FsState*>(user);
  std::string real = inside_folder(fs, path);
  if (real.empty()) {
    if (err) *err += "not a file in the scene's folder";
    return false;
  }
  std::ifstream in(real, std::ios::binary | std::ios::ate);
  std::streamoff size = in ? std::streamoff(in.tellg()) : -1;
  if (size < 0 || size_t(size) > fs.ctx->limits.max_file_bytes) {
    if (err) *err += "cannot read it, or it is over the file size limit";
    return false;
  }
  out->resize(size_t(size));
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(out->data()), size)) return false;
  fs.read->push_back(real);
  return true;
}

bool write_whole_file(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "the loader writes no files";
  return false;
}

struct ImageState {
  const Context* ctx;
  const Checked* checked;
  Images* images;
  size_t texture_bytes = 0;
  std::string error;  // a located error from the callback, thrown once tinygltf returns
};

bool load_image(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                const unsigned char* bytes, int size, void* user) {
  ImageState& s = *static_cast<ImageState*>(user);
  const size_t i = size_t(index);
  if (i >= s.checked->decode_image.size() || !s.checked->decode_image[i]) return true;  // nobody reads it
  const std::string path = "/images/" + std::to_string(index);
  try {
    if (!bytes || size <= 0) throw std::runtime_error("the image is empty");
    TextureDesc t;
    t.name = image->name.empty() ? path : image->name;
    t.texels = decode_image_rgb8(bytes, size_t(size), s.ctx->limits.max_texture_pixels, t.width, t.height, &t.alpha);
    s.texture_bytes += t.texels.size() + t.alpha.size();
    if (s.texture_bytes > s.ctx->limits.max_texture_bytes)
      throw std::runtime_error("the textures take more than " + std::to_string(s.ctx->limits.max_texture_bytes) +
                               " bytes decoded");
    s.images->images[i] = std::move(t);
    s.images->ok[i] = true;
    return true;
  } catch (const std::exception& e) {
    s.error = s.ctx->name + ": " + path + ": " + e.what();
    return false;
  }
}

}  // namespace

tinygltf::Model run_tinygltf(const Context& ctx, const std::string& bytes, const Parts& parts, const Checked& checked,
                             Images& images, std::vector<std::string>& files_read) {
  tinygltf::TinyGLTF loader;
  FsState fs{&ctx, "", &files_read};
  if (!ctx.base_dir.empty()) {
    char buf[PATH_MAX];
    if (realpath(ctx.base_dir.c_str(), buf)) fs.folder = buf;
  }
  loader.SetFsCallbacks({&file_exists, &expand_path, &read_whole_file, &write_whole_file, &fs});
  tinygltf::Model model;
  images.images.assign(checked.decode_image.size(), TextureDesc());
  images.ok.assign(checked.decode_image.size(), false);
  ImageState state{&ctx, &checked, &images, 0, ""};
  loader.SetImageLoader(&load_image, &state);
  std::string err, warn;
  const std::string base = fs.folder.empty() ? std::string("/nonexistent") : fs.folder;
  bool ok = ctx.binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                                     unsigned(bytes.size()), base, tinygltf::REQUIRE_VERSION)
                       : loader.LoadASCIIFromString(&model, &err, &warn, parts.json.data(), unsigned(parts.json.size()),
                                                    base, tinygltf::REQUIRE_VERSION);
  if (!state.error.empty()) throw SceneError(state.error);
  if (!ok) {  // what the checks let through: tinygltf's words, which name no place
    std::string msg = clip(err, 300);
    for (char& c : msg)
      if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = ' ';
    throw SceneError(ctx.name + ": tinygltf: " + msg);
  }
  return model;
}

}  // namespace pt::gltf_detail
