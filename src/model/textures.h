// Procedurally generated textures (no image files ship with Cradle) and their MJCF elements.
// A texture's images are written as PNG files beside scene.xml, named tex_<name>[_<face>].png.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/image.h"
#include "model/infant.h"

namespace cradle::model {

using cradle::Image;

struct TextureAsset {
  std::string name;
  std::string type;  // "2d" or "cube"
  // MJCF file attribute -> image: "file" for 2d; "fileright" (+x), "fileleft" (-x), "fileup" (+y),
  // "filedown" (-y), "filefront" (+z), "fileback" (-z) for cube faces. Missing cube faces take
  // rgb1.
  std::vector<std::pair<std::string, Image>> files;
  std::string attributes;  // extra MJCF attributes, e.g. rgb1="0.95 0.8 0.5"
};

struct MaterialAsset {
  std::string name;
  std::string texture;     // empty: untextured
  std::string attributes;  // e.g. rgba="..." specular=".15"
};

// File name of one image of a texture: tex_<name>.png for "file", else tex_<name>_<face>.png with
// the attribute's "file" prefix dropped, e.g. tex_head_default_right.png for "fileright".
std::string texture_file_name(const TextureAsset& texture, const std::string& attribute);

// <texture .../> element referring to the PNG files by texture_file_name.
std::string texture_xml(const TextureAsset& texture);
std::string material_xml(const MaterialAsset& material);

using cradle::encode_png;

// The infant's textures and materials. Material names used by the body tables: skin, head,
// eye_left, eye_right, top_up, top_middle, top_down, sleeve, pants_up, pants_down, sock. Head
// textures: one cube map per facial expression, named head_texture_name(emote) = head_<emote>
// (files tex_head_<emote>_<face>.png); the "head" material uses head_default. Eye textures eye_left
// and eye_right, sleeve texture sleeve. v1 and v2 share everything for now.
std::vector<TextureAsset> infant_textures(MimoVersion version);
std::vector<MaterialAsset> infant_materials(MimoVersion version);

// Facial expressions available as head textures: default, happy, sad, surprised, angry,
// disgusted, scared.
const std::vector<std::string>& emote_names();

// Name of the head texture showing an expression: head_<emote>.
std::string head_texture_name(const std::string& emote);

}  // namespace cradle::model
