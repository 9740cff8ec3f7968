// Tests of the procedural infant textures: PNG encoding, naming, MJCF elements, and that MuJoCo
// 2.2.2 loads the generated files within the texture memory budget.
#include "model/textures.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <stb_image.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

namespace cradle::model {
namespace {

// The texture with a given name, or nullptr.
const TextureAsset* find_texture(const std::vector<TextureAsset>& textures,
                                 const std::string& name) {
  const auto it = std::find_if(textures.begin(), textures.end(),
                               [&](const TextureAsset& t) { return t.name == name; });
  return it == textures.end() ? nullptr : &*it;
}

// The image of a texture for an MJCF file attribute, or nullptr.
const Image* find_image(const TextureAsset& texture, const std::string& attribute) {
  for (const auto& [name, image] : texture.files) {
    if (name == attribute) return &image;
  }
  return nullptr;
}

// The MJCF file attributes a texture provides.
std::vector<std::string> attributes_of(const TextureAsset& texture) {
  std::vector<std::string> out;
  for (const auto& [name, image] : texture.files) out.push_back(name);
  return out;
}

// RGB of one pixel.
std::vector<int> pixel(const Image& image, int row, int col) {
  const std::size_t i = (static_cast<std::size_t>(row) * image.width + col) * 3;
  return {image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]};
}

// A fresh, uniquely named directory under the system temp directory, removed on destruction.
class TempDir {
 public:
  TempDir() {
    const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
    path_ = std::filesystem::temp_directory_path() /
            ("cradle_textures_test_" + std::to_string(::getpid()) + "_" + std::to_string(stamp));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

TEST(EncodePng, RoundTripsPixelsAndSize) {
  Image image{37, 23, {}};  // odd sizes catch stride mistakes
  for (int row = 0; row < image.height; ++row) {
    for (int col = 0; col < image.width; ++col) {
      image.rgb.push_back(static_cast<std::uint8_t>(col * 7));
      image.rgb.push_back(static_cast<std::uint8_t>(row * 11));
      image.rgb.push_back(static_cast<std::uint8_t>((row * col) % 256));
    }
  }
  const std::vector<std::uint8_t> png = encode_png(image);
  ASSERT_GT(png.size(), 8u);
  int width = 0, height = 0, channels = 0;
  stbi_uc* decoded = stbi_load_from_memory(png.data(), static_cast<int>(png.size()), &width,
                                           &height, &channels, 3);
  ASSERT_NE(decoded, nullptr);
  EXPECT_EQ(width, image.width);
  EXPECT_EQ(height, image.height);
  EXPECT_EQ(channels, 3);
  const std::vector<std::uint8_t> pixels(decoded, decoded + image.rgb.size());
  stbi_image_free(decoded);
  EXPECT_EQ(pixels, image.rgb);
}

TEST(TextureFileName, UsesFaceWithoutFilePrefix) {
  const TextureAsset texture{"head_default", "cube", {}, ""};
  EXPECT_EQ(texture_file_name(texture, "file"), "tex_head_default.png");
  EXPECT_EQ(texture_file_name(texture, "fileright"), "tex_head_default_right.png");
  EXPECT_EQ(texture_file_name(texture, "fileback"), "tex_head_default_back.png");
}

TEST(TextureXml, ListsFilesAndAttributes) {
  TextureAsset flat{"rug", "2d", {}, ""};
  flat.files.emplace_back("file", Image{1, 1, {0, 0, 0}});
  EXPECT_EQ(texture_xml(flat), R"(<texture name="rug" type="2d" file="tex_rug.png"/>)");

  TextureAsset cube{"eye", "cube", {}, R"(rgb1="1 1 1")"};
  cube.files.emplace_back("fileright", Image{1, 1, {0, 0, 0}});
  cube.files.emplace_back("fileup", Image{1, 1, {0, 0, 0}});
  EXPECT_EQ(texture_xml(cube), R"(<texture name="eye" type="cube" fileright="tex_eye_right.png" )"
                               R"(fileup="tex_eye_up.png" rgb1="1 1 1"/>)");
}

TEST(MaterialXml, NamesTextureWhenSet) {
  EXPECT_EQ(material_xml({"skin", "", R"(rgba="1 0 0 1")"}),
            R"(<material name="skin" rgba="1 0 0 1"/>)");
  EXPECT_EQ(material_xml({"head", "head_default", ""}),
            R"(<material name="head" texture="head_default"/>)");
}

TEST(EmoteNames, ListsTheSevenExpressions) {
  const std::vector<std::string> expected = {"default", "happy",     "sad",   "surprised",
                                             "angry",   "disgusted", "scared"};
  EXPECT_EQ(emote_names(), expected);
  EXPECT_EQ(head_texture_name("happy"), "head_happy");
}

TEST(InfantTextures, ImagesAreSquareRgbOfOneSizePerTexture) {
  for (const TextureAsset& texture : infant_textures(MimoVersion::kV1)) {
    SCOPED_TRACE(texture.name);
    ASSERT_FALSE(texture.files.empty());
    EXPECT_EQ(texture.type, "cube");
    const int size = texture.files.front().second.width;
    EXPECT_GT(size, 0);
    for (const auto& [attribute, image] : texture.files) {
      EXPECT_EQ(image.width, size) << attribute;
      EXPECT_EQ(image.height, size) << attribute;
      EXPECT_EQ(image.rgb.size(), static_cast<std::size_t>(image.width) * image.height * 3)
          << attribute;
    }
  }
}

TEST(InfantTextures, HeadHasFiveFacesPerEmote) {
  const auto textures = infant_textures(MimoVersion::kV1);
  const std::vector<std::string> faces = {"fileright", "fileleft", "fileup", "filedown",
                                          "filefront"};
  for (const std::string& emote : emote_names()) {
    const TextureAsset* head = find_texture(textures, head_texture_name(emote));
    ASSERT_NE(head, nullptr) << emote;
    EXPECT_EQ(head->type, "cube");
    EXPECT_EQ(attributes_of(*head), faces) << emote;  // -z (fileback) stays unset
    EXPECT_NE(head->attributes.find(R"(rgb1="0.95 0.8 0.5")"), std::string::npos);
  }
}

TEST(InfantTextures, EyesHaveOnlyThePupilFaceOverWhite) {
  const auto textures = infant_textures(MimoVersion::kV1);
  for (const std::string name : {"eye_left", "eye_right"}) {
    const TextureAsset* eye = find_texture(textures, name);
    ASSERT_NE(eye, nullptr) << name;
    EXPECT_EQ(attributes_of(*eye), std::vector<std::string>{"fileright"});
    EXPECT_NE(eye->attributes.find(R"(rgb1="1 1 1")"), std::string::npos);
    const Image& face = eye->files.front().second;
    const int mid = face.width / 2;
    // Dark pupil in the middle, symmetric around it; white sclera in the corners.
    for (int value : pixel(face, mid, mid)) EXPECT_LT(value, 40);
    EXPECT_EQ(pixel(face, mid - 3, mid), pixel(face, mid + 2, mid));
    EXPECT_EQ(pixel(face, 0, 0), (std::vector<int>{255, 255, 255}));
    EXPECT_EQ(pixel(face, face.width - 1, face.width - 1), (std::vector<int>{255, 255, 255}));
  }
}

TEST(InfantTextures, FileNamesAreUnique) {
  std::set<std::string> names;
  std::size_t count = 0;
  for (const TextureAsset& texture : infant_textures(MimoVersion::kV1)) {
    for (const auto& [attribute, image] : texture.files) {
      names.insert(texture_file_name(texture, attribute));
      ++count;
    }
  }
  EXPECT_EQ(names.size(), count);
}

TEST(InfantMaterials, CoverTheBodyTablesAndReferToExistingTextures) {
  const auto textures = infant_textures(MimoVersion::kV1);
  const auto materials = infant_materials(MimoVersion::kV1);
  std::set<std::string> names;
  for (const MaterialAsset& material : materials) {
    EXPECT_TRUE(names.insert(material.name).second) << "duplicate " << material.name;
    if (!material.texture.empty()) {
      EXPECT_NE(find_texture(textures, material.texture), nullptr) << material.name;
    }
  }
  for (const std::string name : {"skin", "head", "eye_left", "eye_right", "top_up", "top_middle",
                                 "top_down", "sleeve", "pants_up", "pants_down", "sock"}) {
    EXPECT_TRUE(names.contains(name)) << name;
  }
  const auto head = std::find_if(materials.begin(), materials.end(),
                                 [](const MaterialAsset& m) { return m.name == "head"; });
  ASSERT_NE(head, materials.end());
  EXPECT_EQ(head->texture, "head_default");
}

TEST(InfantTextures, LoadInMujocoWithinBudget) {
  const auto textures = infant_textures(MimoVersion::kV1);
  const auto materials = infant_materials(MimoVersion::kV1);
  const TempDir dir;
  std::string xml = "<mujoco>\n  <asset>\n";
  for (const TextureAsset& texture : textures) {
    xml += "    " + texture_xml(texture) + "\n";
    for (const auto& [attribute, image] : texture.files) {
      const std::vector<std::uint8_t> png = encode_png(image);
      std::ofstream file(dir.path() / texture_file_name(texture, attribute), std::ios::binary);
      file.write(reinterpret_cast<const char*>(png.data()),
                 static_cast<std::streamsize>(png.size()));
      ASSERT_TRUE(file.good());
    }
  }
  for (const MaterialAsset& material : materials) xml += "    " + material_xml(material) + "\n";
  xml += "  </asset>\n  <worldbody>\n";
  xml += "    <geom type=\"sphere\" size=\"0.0735\" material=\"head\"/>\n";
  xml += "  </worldbody>\n</mujoco>\n";
  const std::filesystem::path scene = dir.path() / "scene.xml";
  std::ofstream(scene) << xml;

  char error[1000] = "";
  mjModel* model = mj_loadXML(scene.c_str(), nullptr, error, sizeof(error));
  ASSERT_NE(model, nullptr) << error;
  EXPECT_STREQ(error, "");
  EXPECT_EQ(model->ntex, static_cast<int>(textures.size()));
  EXPECT_EQ(model->nmat, static_cast<int>(materials.size()));
  EXPECT_LE(model->ntexdata, 8 * 1024 * 1024);
  for (int i = 0; i < model->ntex; ++i) EXPECT_EQ(model->tex_type[i], mjTEXTURE_CUBE);
  mj_deleteModel(model);
}

TEST(InfantTextures, AreDeterministic) {
  const auto first = infant_textures(MimoVersion::kV1);
  const auto second = infant_textures(MimoVersion::kV1);
  ASSERT_EQ(first.size(), second.size());
  for (std::size_t i = 0; i < first.size(); ++i) {
    ASSERT_EQ(first[i].files.size(), second[i].files.size());
    for (std::size_t j = 0; j < first[i].files.size(); ++j) {
      EXPECT_EQ(first[i].files[j].second.rgb, second[i].files[j].second.rgb) << first[i].name;
      EXPECT_EQ(encode_png(first[i].files[j].second), encode_png(second[i].files[j].second));
    }
  }
}

TEST(InfantTextures, VersionsShareTextures) {
  const auto v1 = infant_textures(MimoVersion::kV1);
  const auto v2 = infant_textures(MimoVersion::kV2);
  ASSERT_EQ(v1.size(), v2.size());
  for (std::size_t i = 0; i < v1.size(); ++i) {
    EXPECT_EQ(v1[i].name, v2[i].name);
    EXPECT_EQ(texture_xml(v1[i]), texture_xml(v2[i]));
  }
}

TEST(InfantTextures, FacesDifferBetweenEmotesOnlyOnTheFront) {
  const auto textures = infant_textures(MimoVersion::kV1);
  const auto& emotes = emote_names();
  for (std::size_t a = 0; a < emotes.size(); ++a) {
    const TextureAsset* first = find_texture(textures, head_texture_name(emotes[a]));
    ASSERT_NE(first, nullptr);
    for (std::size_t b = a + 1; b < emotes.size(); ++b) {
      const TextureAsset* second = find_texture(textures, head_texture_name(emotes[b]));
      ASSERT_NE(second, nullptr);
      EXPECT_NE(find_image(*first, "fileright")->rgb, find_image(*second, "fileright")->rgb)
          << emotes[a] << " vs " << emotes[b];
      for (const std::string face : {"fileleft", "fileup", "filedown", "filefront"}) {
        EXPECT_EQ(find_image(*first, face)->rgb, find_image(*second, face)->rgb) << face;
      }
    }
  }
}

}  // namespace
}  // namespace cradle::model
