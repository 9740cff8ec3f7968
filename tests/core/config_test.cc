// Tests for the config module: reference YAMLs, defaults, aliases, every error case, round trips.
#include "core/config.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <string>
#include <vector>

#include "core/error.h"

#ifndef CRADLE_SOURCE_DIR
#error "CRADLE_SOURCE_DIR must be defined as the repository root"
#endif

namespace cradle {
namespace {

const std::filesystem::path kConfigDir = std::filesystem::path(CRADLE_SOURCE_DIR) / "configs";

// The 43 keys of the API page, spelled as there.
const std::vector<std::string> kDocKeys = {
    "save_dir",          "behavior",          "scene",
    "max_episode_steps", "frame_skip",        "render_size",
    "save_logs_every",   "proprio_velocity",  "proprio_torque",
    "proprio_limits",    "proprio_actuation", "vestibular_active",
    "vision_active",     "vision_resolution", "touch_active",
    "touch_scale",       "touch_function",    "touch_response",
    "touch_hands",       "touch_fingers",     "touch_arms",
    "touch_feet",        "touch_legs",        "touch_body",
    "touch_head",        "touch_eyes",        "actuation_model",
    "act_hands",         "act_fingers",       "act_arms",
    "act_feet",          "act_legs",          "act_body",
    "act_head",          "act_eyes",          "lock_hands",
    "lock_fingers",      "lock_arms",         "lock_feet",
    "lock_legs",         "lock_body",         "lock_head",
    "lock_eyes"};

// Flags with exactly the listed groups set.
GroupFlags only(std::initializer_list<Group> groups) {
  GroupFlags flags = GroupFlags::all(false);
  for (Group g : groups) flags[g] = true;
  return flags;
}

// Flags with every group set except the listed ones.
GroupFlags all_but(std::initializer_list<Group> groups) {
  GroupFlags flags = GroupFlags::all(true);
  for (Group g : groups) flags[g] = false;
  return flags;
}

// Values shared by the three reference YAMLs (babybench_layer.md §5).
Config reference_common() {
  Config c;
  c.max_episode_steps = 1000;
  c.frame_skip = 1;
  c.render_size = 480;
  c.save_logs_every = 1000;
  c.vision_resolution = 64;
  c.touch_scale = 1.0;
  c.touch_function = TouchFunction::kForceVector;
  c.touch_response = TouchResponse::kSpreadLinear;
  c.touch_groups = all_but({Group::kEyes});
  c.actuation_model = ActuationModel::kSpringDamper;
  return c;
}

// Parses text and returns the UserError message; fails the test if nothing is thrown.
std::string error_of(const std::string& yaml, const std::string& source = "config.yml") {
  try {
    parse_config(yaml, source);
  } catch (const UserError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no UserError for:\n" << yaml;
  return "";
}

// Asserts the message is one line, starts with the source and contains every part.
void expect_message(const std::string& message, std::initializer_list<std::string> parts,
                    const std::string& source = "config.yml") {
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(message.rfind(source + ":", 0), 0u) << message;
  for (const std::string& part : parts) {
    EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
  }
}

// Writes text to a fresh file under the test temp dir.
std::filesystem::path write_temp(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::path(::testing::TempDir()) / name;
  std::ofstream(path) << text;
  return path;
}

TEST(ConfigReference, TestInstallationHasSection5Values) {
  const Config c = load_config(kConfigDir / "config_test_installation.yml");
  Config want = reference_common();
  want.save_dir = "results/test_installation";
  want.behavior = Behavior::kNone;
  want.scene = SceneKind::kBase;
  want.vestibular_active = true;
  want.vision_active = true;
  want.touch_active = true;
  want.act_groups = GroupFlags::all(true);
  want.lock_groups = only({Group::kFeet});
  EXPECT_EQ(c, want);
  EXPECT_EQ(c.scene, SceneKind::kBase);
  EXPECT_TRUE(c.lock_groups[Group::kFeet]);
  EXPECT_TRUE(c.act_groups[Group::kFeet]);
  EXPECT_FALSE(c.touch_groups[Group::kEyes]);
  EXPECT_EQ(c.touch_function, TouchFunction::kForceVector);
}

TEST(ConfigReference, SelfTouchHasSection5Values) {
  const Config c = load_config(kConfigDir / "config_selftouch.yml");
  Config want = reference_common();
  want.save_dir = "results/self_touch";
  want.behavior = Behavior::kSelfTouch;
  want.scene = SceneKind::kCrib;
  want.vestibular_active = true;
  want.vision_active = false;
  want.touch_active = true;
  want.act_groups = all_but({Group::kFeet, Group::kEyes});
  want.lock_groups = only({Group::kFeet, Group::kEyes});
  EXPECT_EQ(c, want);
  EXPECT_EQ(c.behavior, Behavior::kSelfTouch);
  EXPECT_FALSE(c.vision_active);
  EXPECT_TRUE(c.vestibular_active);
  EXPECT_FALSE(c.act_groups[Group::kEyes]);
  EXPECT_TRUE(c.lock_groups[Group::kEyes]);
  EXPECT_TRUE(c.touch_enabled());
}

TEST(ConfigReference, HandRegardHasSection5Values) {
  const Config c = load_config(kConfigDir / "config_handregard.yml");
  Config want = reference_common();
  want.save_dir = "results/hand_regard";
  want.behavior = Behavior::kHandRegard;
  want.scene = SceneKind::kCubes;
  want.vestibular_active = false;
  want.vision_active = true;
  want.touch_active = false;
  want.act_groups = only({Group::kHands, Group::kArms, Group::kHead});
  want.lock_groups = only({Group::kFeet, Group::kLegs, Group::kBody, Group::kEyes});
  EXPECT_EQ(c, want);
  EXPECT_EQ(c.behavior, Behavior::kHandRegard);
  EXPECT_EQ(c.scene, SceneKind::kCubes);
  EXPECT_FALSE(c.act_groups[Group::kFingers]);
  EXPECT_TRUE(c.lock_groups[Group::kBody]);
  EXPECT_FALSE(c.lock_groups[Group::kFingers]);
  EXPECT_TRUE(c.vision_active);
  EXPECT_FALSE(c.touch_active);
  EXPECT_FALSE(c.touch_enabled());
}

TEST(ConfigReference, FilesSetEveryDocKeyOnce) {
  // Like the reference kit's YAMLs, each file spells out all 43 documented keys, each once.
  for (const char* name :
       {"config_test_installation.yml", "config_selftouch.yml", "config_handregard.yml"}) {
    std::ifstream in(kConfigDir / name);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (const std::string& key : kDocKeys) {
      const std::string line = "\n" + key + ": ";
      const size_t first = text.find(line);
      EXPECT_NE(first, std::string::npos) << name << " lacks " << key;
      EXPECT_EQ(text.find(line, first + 1), std::string::npos) << name << " repeats " << key;
    }
  }
}

TEST(ConfigDefaults, DefaultConfigHasDocumentedDefaults) {
  const Config c = default_config();
  EXPECT_EQ(c.save_dir, "results/test_installation");
  EXPECT_EQ(c.behavior, Behavior::kNone);
  EXPECT_EQ(c.scene, SceneKind::kBase);
  EXPECT_EQ(c.max_episode_steps, 1000);
  EXPECT_EQ(c.frame_skip, 1);
  EXPECT_EQ(c.render_size, 480);
  EXPECT_EQ(c.save_logs_every, 1000);
  EXPECT_TRUE(c.proprio_velocity && c.proprio_torque && c.proprio_limits && c.proprio_actuation);
  EXPECT_TRUE(c.vestibular_active);
  EXPECT_TRUE(c.vision_active);
  EXPECT_EQ(c.vision_resolution, 64);
  EXPECT_TRUE(c.touch_active);
  EXPECT_EQ(c.touch_scale, 1.0);
  EXPECT_EQ(c.touch_function, TouchFunction::kNormal);
  EXPECT_EQ(c.touch_response, TouchResponse::kNearest);
  EXPECT_EQ(c.touch_groups, all_but({Group::kEyes}));
  EXPECT_EQ(c.actuation_model, ActuationModel::kSpringDamper);
  EXPECT_EQ(c.act_groups, GroupFlags::all(true));
  EXPECT_EQ(c.lock_groups, GroupFlags::all(false));
  EXPECT_EQ(c.hand_regard_half_angle, 15.0);
  EXPECT_FALSE(c.hand_regard_occlusion);
  EXPECT_FALSE(c.mattress_friction_applies);  // the reference's crib dynamics
}

TEST(ConfigDefaults, EmptyInputsGiveDefaults) {
  EXPECT_EQ(parse_config("{}", "x.yml"), default_config());
  EXPECT_EQ(parse_config("", "x.yml"), default_config());
  EXPECT_EQ(parse_config("# nothing here\n", "x.yml"), default_config());
}

TEST(ConfigDefaults, MissingKeysKeepDefaults) {
  const Config c = parse_config("scene: crib\nframe_skip: 4\nlock_head: True\n", "x.yml");
  Config want = default_config();
  want.scene = SceneKind::kCrib;
  want.frame_skip = 4;
  want.lock_groups[Group::kHead] = true;
  EXPECT_EQ(c, want);
}

TEST(ConfigValues, BehaviorAliases) {
  EXPECT_EQ(parse_config("behavior: selftouch", "x").behavior, Behavior::kSelfTouch);
  EXPECT_EQ(parse_config("behavior: self_touch", "x").behavior, Behavior::kSelfTouch);
  EXPECT_EQ(parse_config("behavior: handregard", "x").behavior, Behavior::kHandRegard);
  EXPECT_EQ(parse_config("behavior: hand_regard", "x").behavior, Behavior::kHandRegard);
  EXPECT_EQ(parse_config("behavior: none", "x").behavior, Behavior::kNone);
  EXPECT_EQ(parse_config("behavior: 'hand_regard'", "x").behavior, Behavior::kHandRegard);
}

TEST(ConfigValues, BooleanSpellings) {
  for (const char* text : {"True", "true", "TRUE", "tRuE", "yes", "On"}) {
    EXPECT_TRUE(
        parse_config(std::string("hand_regard_occlusion: ") + text, "x").hand_regard_occlusion)
        << text;
  }
  for (const char* text : {"False", "false", "FALSE", "no", "OFF", "!!bool false"}) {
    EXPECT_FALSE(parse_config(std::string("vision_active: ") + text, "x").vision_active) << text;
  }
  EXPECT_TRUE(parse_config("mattress_friction_applies: True", "x").mattress_friction_applies);
  try {
    parse_config("mattress_friction_applies: 0.1", "x.yml");
    ADD_FAILURE() << "a number for a boolean key was accepted";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("mattress_friction_applies"), std::string::npos)
        << e.what();
  }
}

TEST(ConfigValues, NumberSpellings) {
  EXPECT_EQ(parse_config("touch_scale: 1.", "x").touch_scale, 1.0);
  EXPECT_EQ(parse_config("touch_scale: 2", "x").touch_scale, 2.0);
  EXPECT_EQ(parse_config("touch_scale: .5", "x").touch_scale, 0.5);
  EXPECT_EQ(parse_config("touch_scale: +2.5e-1", "x").touch_scale, 0.25);
  EXPECT_EQ(parse_config("touch_scale: 0", "x").touch_scale, 0.0);
  EXPECT_FALSE(std::signbit(parse_config("touch_scale: -0.0", "x").touch_scale));
  EXPECT_EQ(parse_config("frame_skip: +3", "x").frame_skip, 3);
  EXPECT_EQ(parse_config("max_episode_steps: 2147483647", "x").max_episode_steps, 2147483647);
  EXPECT_EQ(parse_config("hand_regard_half_angle: 90", "x").hand_regard_half_angle, 90.0);
  EXPECT_EQ(parse_config("render_size: 16", "x").render_size, 16);
  EXPECT_EQ(parse_config("vision_resolution: 1024", "x").vision_resolution, 1024);
}

TEST(ConfigValues, EnumKeysReadEveryOption) {
  EXPECT_EQ(parse_config("scene: cubes", "x").scene, SceneKind::kCubes);
  EXPECT_EQ(parse_config("actuation_model: muscle", "x").actuation_model, ActuationModel::kMuscle);
  EXPECT_EQ(parse_config("actuation_model: positional", "x").actuation_model,
            ActuationModel::kPositional);
  EXPECT_EQ(parse_config("touch_function: force_vector_global", "x").touch_function,
            TouchFunction::kForceVectorGlobal);
  EXPECT_EQ(parse_config("touch_response: spread_linear", "x").touch_response,
            TouchResponse::kSpreadLinear);
}

TEST(ConfigValues, TouchEnabledNeedsActiveAndPositiveScale) {
  EXPECT_TRUE(parse_config("touch_scale: 0.5", "x").touch_enabled());
  EXPECT_FALSE(parse_config("touch_scale: 0", "x").touch_enabled());
  EXPECT_FALSE(parse_config("touch_active: False", "x").touch_enabled());
}

TEST(ConfigNames, NamesAndLookups) {
  EXPECT_EQ(behavior_name(Behavior::kNone), "none");
  EXPECT_EQ(behavior_name(Behavior::kSelfTouch), "self_touch");
  EXPECT_EQ(behavior_name(Behavior::kHandRegard), "hand_regard");
  EXPECT_EQ(scene_name(SceneKind::kBase), "base");
  EXPECT_EQ(scene_name(SceneKind::kCrib), "crib");
  EXPECT_EQ(scene_name(SceneKind::kCubes), "cubes");
  EXPECT_EQ(actuation_model_name(ActuationModel::kSpringDamper), "spring_damper");
  EXPECT_EQ(actuation_model_name(ActuationModel::kMuscle), "muscle");
  EXPECT_EQ(actuation_model_name(ActuationModel::kPositional), "positional");
  EXPECT_EQ(touch_function_name(TouchFunction::kNormal), "normal");
  EXPECT_EQ(touch_function_name(TouchFunction::kForceVector), "force_vector");
  EXPECT_EQ(touch_function_name(TouchFunction::kForceVectorGlobal), "force_vector_global");
  EXPECT_EQ(touch_response_name(TouchResponse::kNearest), "nearest");
  EXPECT_EQ(touch_response_name(TouchResponse::kSpreadLinear), "spread_linear");
  EXPECT_EQ(behavior_from_name("handregard"), Behavior::kHandRegard);
  EXPECT_EQ(behavior_from_name("Self_Touch"), std::nullopt);
  EXPECT_EQ(scene_from_name("crib"), SceneKind::kCrib);
  EXPECT_EQ(actuation_model_from_name("motor"), std::nullopt);
  EXPECT_EQ(touch_function_from_name("normal"), TouchFunction::kNormal);
  EXPECT_EQ(touch_response_from_name("spread_linear"), TouchResponse::kSpreadLinear);
}

TEST(ConfigNames, KeysAreDocKeysThenExtensions) {
  std::vector<std::string> want = kDocKeys;
  want.push_back("hand_regard_half_angle");
  want.push_back("hand_regard_occlusion");
  want.push_back("mattress_friction_applies");
  const auto keys = config_keys();
  EXPECT_EQ(std::vector<std::string>(keys.begin(), keys.end()), want);
}

TEST(ConfigErrors, MissingFile) {
  const auto path = std::filesystem::path(::testing::TempDir()) / "no_such_config.yml";
  try {
    load_config(path);
    FAIL() << "no error";
  } catch (const UserError& e) {
    expect_message(e.what(), {"cannot read config file", "no such file"}, path.string());
  }
}

TEST(ConfigErrors, DirectoryInsteadOfFile) {
  try {
    load_config(kConfigDir);
    FAIL() << "no error";
  } catch (const UserError& e) {
    expect_message(e.what(), {"cannot read config file", "directory"}, kConfigDir.string());
  }
}

TEST(ConfigErrors, FileErrorsNameTheFile) {
  const auto path = write_temp("bad_frame_skip.yml", "scene: crib\nframe_skip: abc\n");
  try {
    load_config(path);
    FAIL() << "no error";
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()),
              path.string() + ": key 'frame_skip' must be an integer, got 'abc'");
  }
}

TEST(ConfigErrors, SyntaxErrorHasLineNumber) {
  const std::string message = error_of("scene: crib\nframe_skip: 1\n  render_size: 2\n");
  EXPECT_EQ(message, "config.yml: YAML syntax error at line 3, column 14: illegal map value");
  const std::string flow = error_of("scene: crib\nlock_eyes: [True\n");
  expect_message(flow, {"YAML syntax error", "line "});
}

TEST(ConfigErrors, TopLevelNotMapping) {
  expect_message(error_of("- scene\n- crib\n"), {"top level must be a mapping", "got a list"});
  expect_message(error_of("just text\n"), {"top level must be a mapping", "got 'just text'"});
}

TEST(ConfigErrors, SeveralDocuments) {
  expect_message(error_of("scene: crib\n---\nscene: base\n"), {"single YAML document", "found 2"});
}

TEST(ConfigErrors, UnknownKeyWithSuggestion) {
  EXPECT_EQ(error_of("vision_resoluton: 64\n"),
            "config.yml: unknown key 'vision_resoluton'; did you mean 'vision_resolution'?");
  EXPECT_EQ(error_of("behaviour: none\n"),
            "config.yml: unknown key 'behaviour'; did you mean 'behavior'?");
  EXPECT_EQ(error_of("Frame_Skip: 1\n"),
            "config.yml: unknown key 'Frame_Skip'; did you mean 'frame_skip'?");
  EXPECT_EQ(error_of("resolution: 64\n"),
            "config.yml: unknown key 'resolution'; did you mean 'vision_resolution'?");
}

TEST(ConfigErrors, UnknownKeyWithoutSuggestion) {
  EXPECT_EQ(error_of("learning_rate: 0.1\n"),
            "config.yml: unknown key 'learning_rate' (not a BabyBench or Cradle config key)");
}

TEST(ConfigErrors, NonScalarKey) {
  expect_message(error_of("[a, b]: 1\n"), {"every key must be a plain name", "got a list"});
}

TEST(ConfigErrors, DuplicateKey) {
  EXPECT_EQ(error_of("scene: crib\nframe_skip: 1\nscene: base\n"),
            "config.yml: key 'scene' is set twice (lines 1 and 3)");
}

TEST(ConfigErrors, IntegerWrongType) {
  EXPECT_EQ(error_of("frame_skip: abc\n"),
            "config.yml: key 'frame_skip' must be an integer, got 'abc'");
  EXPECT_EQ(error_of("frame_skip: 2.5\n"),
            "config.yml: key 'frame_skip' must be an integer, got '2.5'");
  EXPECT_EQ(error_of("render_size: \"480\"\n"),
            "config.yml: key 'render_size' must be an integer, got \"480\" (a quoted string)");
  expect_message(error_of("max_episode_steps: True\n"),
                 {"'max_episode_steps'", "an integer", "'True'"});
  expect_message(error_of("save_logs_every: [1]\n"),
                 {"'save_logs_every'", "an integer", "got a list"});
  expect_message(error_of("frame_skip: +-2\n"), {"'frame_skip'", "an integer", "'+-2'"});
  expect_message(error_of("vision_resolution: 0x40\n"),
                 {"'vision_resolution'", "an integer", "'0x40'"});
}

TEST(ConfigErrors, IntegerOutOfRange) {
  EXPECT_EQ(error_of("frame_skip: 0\n"),
            "config.yml: key 'frame_skip' must be between 1 and 100, got 0");
  EXPECT_EQ(error_of("max_episode_steps: -5\n"),
            "config.yml: key 'max_episode_steps' must be at least 1, got -5");
  EXPECT_EQ(error_of("save_logs_every: 0\n"),
            "config.yml: key 'save_logs_every' must be at least 1, got 0");
  EXPECT_EQ(error_of("render_size: 15\n"),
            "config.yml: key 'render_size' must be between 16 and 4096, got 15");
  EXPECT_EQ(error_of("render_size: 4097\n"),
            "config.yml: key 'render_size' must be between 16 and 4096, got 4097");
  EXPECT_EQ(error_of("vision_resolution: 0\n"),
            "config.yml: key 'vision_resolution' must be between 1 and 1024, got 0");
  EXPECT_EQ(error_of("vision_resolution: 2048\n"),
            "config.yml: key 'vision_resolution' must be between 1 and 1024, got 2048");
  expect_message(error_of("max_episode_steps: 3000000000\n"),
                 {"'max_episode_steps'", "32 bits", "3000000000"});
  expect_message(error_of("frame_skip: 99999999999999999999999\n"), {"'frame_skip'", "32 bits"});
}

TEST(ConfigErrors, BooleanWrongType) {
  EXPECT_EQ(error_of("vision_active: 1\n"),
            "config.yml: key 'vision_active' must be a boolean (True or False), got '1'");
  EXPECT_EQ(error_of("touch_active: 0\n"),
            "config.yml: key 'touch_active' must be a boolean (True or False), got '0'");
  EXPECT_EQ(error_of("lock_feet: \"True\"\n"),
            "config.yml: key 'lock_feet' must be a boolean (True or False), got \"True\" (a "
            "quoted string)");
  expect_message(error_of("act_eyes: 'false'\n"), {"'act_eyes'", "a boolean", "quoted string"});
  expect_message(error_of("touch_eyes: !!str true\n"), {"'touch_eyes'", "a boolean"});
  expect_message(error_of("proprio_torque: maybe\n"), {"'proprio_torque'", "a boolean", "'maybe'"});
  expect_message(error_of("proprio_limits: y\n"), {"'proprio_limits'", "a boolean", "'y'"});
}

TEST(ConfigErrors, RealWrongTypeOrRange) {
  EXPECT_EQ(error_of("touch_scale: big\n"),
            "config.yml: key 'touch_scale' must be a number, got 'big'");
  EXPECT_EQ(error_of("touch_scale: \"1.\"\n"),
            "config.yml: key 'touch_scale' must be a number, got \"1.\" (a quoted string)");
  EXPECT_EQ(error_of("touch_scale: -0.5\n"),
            "config.yml: key 'touch_scale' must be at least 0, got -0.5");
  EXPECT_EQ(error_of("touch_scale: .inf\n"),
            "config.yml: key 'touch_scale' must be a finite number, got '.inf'");
  expect_message(error_of("touch_scale: .NaN\n"), {"'touch_scale'", "finite number"});
  expect_message(error_of("touch_scale: 1e999\n"), {"'touch_scale'", "finite number"});
  expect_message(error_of("touch_scale: +-1\n"), {"'touch_scale'", "a number", "'+-1'"});
  expect_message(error_of("touch_scale: nan\n"), {"'touch_scale'", "a number", "'nan'"});
  EXPECT_EQ(
      error_of("hand_regard_half_angle: 0\n"),
      "config.yml: key 'hand_regard_half_angle' must be greater than 0 and at most 90, got 0");
  EXPECT_EQ(error_of("hand_regard_half_angle: 90.5\n"),
            "config.yml: key 'hand_regard_half_angle' must be greater than 0 and at most 90, got "
            "90.5");
}

TEST(ConfigErrors, UnknownEnumValues) {
  EXPECT_EQ(error_of("behavior: crawl\n"),
            "config.yml: key 'behavior' must be one of none, self_touch, hand_regard (also "
            "accepted: selftouch, handregard); got 'crawl'");
  EXPECT_EQ(error_of("scene: kitchen\n"),
            "config.yml: key 'scene' must be one of base, crib, cubes; got 'kitchen'");
  EXPECT_EQ(error_of("actuation_model: motor\n"),
            "config.yml: key 'actuation_model' must be one of spring_damper, muscle, positional; "
            "got 'motor'");
  EXPECT_EQ(error_of("touch_function: Normal\n"),
            "config.yml: key 'touch_function' must be one of normal, force_vector, "
            "force_vector_global; got 'Normal'");
  EXPECT_EQ(error_of("touch_response: spread\n"),
            "config.yml: key 'touch_response' must be one of nearest, spread_linear; got 'spread'");
  expect_message(error_of("scene: [crib]\n"), {"'scene'", "one of base, crib, cubes", "a list"});
}

TEST(ConfigErrors, NullValues) {
  EXPECT_EQ(error_of("frame_skip:\n"),
            "config.yml: key 'frame_skip' has no value; expected an integer");
  EXPECT_EQ(error_of("vision_active: ~\n"),
            "config.yml: key 'vision_active' has no value; expected a boolean (True or False)");
  EXPECT_EQ(error_of("scene: null\n"),
            "config.yml: key 'scene' has no value; expected one of base, crib, cubes");
  EXPECT_EQ(error_of("touch_scale:\nscene: crib\n"),
            "config.yml: key 'touch_scale' has no value; expected a number");
  EXPECT_EQ(error_of("save_dir:\n"),
            "config.yml: key 'save_dir' has no value; expected a non-empty path");
}

TEST(ConfigErrors, SaveDirShape) {
  EXPECT_EQ(error_of("save_dir: ''\n"),
            "config.yml: key 'save_dir' must be a non-empty path, got ''");
  expect_message(error_of("save_dir: {a: 1}\n"), {"'save_dir'", "a mapping"});
}

TEST(ConfigErrors, MultiLineValueStaysOneLine) {
  expect_message(error_of("scene: |\n  crib\n  base\n"), {"'scene'", "crib\\nbase"});
}

TEST(ConfigRoundTrip, ReferenceConfigs) {
  for (const char* name :
       {"config_test_installation.yml", "config_selftouch.yml", "config_handregard.yml"}) {
    const Config c = load_config(kConfigDir / name);
    EXPECT_EQ(parse_config(to_yaml(c), "round_trip"), c) << name;
  }
}

TEST(ConfigRoundTrip, EveryFieldChanged) {
  Config c;
  c.save_dir = "weird dir/with \"quotes\" \\ #hash: colon\ttab";
  c.behavior = Behavior::kHandRegard;
  c.scene = SceneKind::kCubes;
  c.max_episode_steps = 77;
  c.frame_skip = 3;
  c.render_size = 256;
  c.save_logs_every = 5;
  c.proprio_velocity = false;
  c.proprio_torque = false;
  c.proprio_limits = false;
  c.proprio_actuation = false;
  c.vestibular_active = false;
  c.vision_active = false;
  c.vision_resolution = 128;
  c.touch_active = false;
  c.touch_scale = 0.1;
  c.touch_function = TouchFunction::kForceVectorGlobal;
  c.touch_response = TouchResponse::kSpreadLinear;
  c.touch_groups = only({Group::kEyes, Group::kHead});
  c.actuation_model = ActuationModel::kPositional;
  c.act_groups = only({Group::kLegs});
  c.lock_groups = all_but({Group::kArms});
  c.hand_regard_half_angle = 22.5;
  c.hand_regard_occlusion = true;
  c.mattress_friction_applies = true;
  const Config back = parse_config(to_yaml(c), "round_trip");
  EXPECT_EQ(back, c);
  EXPECT_EQ(back.save_dir, c.save_dir);
  EXPECT_EQ(back.touch_scale, 0.1);
}

TEST(ConfigRoundTrip, RealsKeepFullPrecisionAndADot) {
  for (double scale : {1.0, 0.1, 1e-7, 3e20, 1.0 / 3.0}) {
    Config c;
    c.touch_active = false;  // with touch on, scales outside 0.25..100 are refused
    c.touch_scale = scale;
    const std::string yaml = to_yaml(c);
    const size_t at = yaml.find("\ntouch_scale: ");
    ASSERT_NE(at, std::string::npos);
    EXPECT_NE(yaml.substr(at + 1, yaml.find('\n', at + 1) - at - 1).find('.'), std::string::npos)
        << yaml.substr(at, 30);
    EXPECT_EQ(parse_config(yaml, "round_trip").touch_scale, scale);
  }
}

TEST(ConfigRoundTrip, StringsThatLookLikeOtherTypes) {
  for (const char* dir : {"True", "null", "123", "1.5", "~", "-", ".inf", "yes", "a: b", "- x",
                          "[x]", "@x", "x #y", "ümlaut/ö", "line\nbreak", "/abs/path"}) {
    Config c;
    c.save_dir = dir;
    EXPECT_EQ(parse_config(to_yaml(c), "round_trip").save_dir, dir) << to_yaml(c);
  }
}

TEST(ConfigRoundTrip, YamlUsesReferenceSpelling) {
  const std::string yaml = "\n" + to_yaml(load_config(kConfigDir / "config_handregard.yml"));
  for (const std::string& key : kDocKeys) {
    EXPECT_NE(yaml.find("\n" + key + ": "), std::string::npos) << key;
  }
  EXPECT_EQ(yaml.rfind("\nsave_dir: results/hand_regard\n", 0), 0u) << yaml;
  EXPECT_NE(yaml.find("\nbehavior: hand_regard\n"), std::string::npos);
  EXPECT_NE(yaml.find("\nvision_active: True\n"), std::string::npos);
  EXPECT_NE(yaml.find("\ntouch_active: False\n"), std::string::npos);
  EXPECT_NE(yaml.find("\ntouch_scale: 1.0\n"), std::string::npos);
  EXPECT_NE(yaml.find("\nact_fingers: False\n"), std::string::npos);
  EXPECT_NE(yaml.find("\nhand_regard_half_angle: 15.0\n"), std::string::npos);
}

TEST(ConfigJson, HasEveryKeyWithValues) {
  const Config c = load_config(kConfigDir / "config_selftouch.yml");
  const nlohmann::json j = to_json(c);
  const auto keys = config_keys();
  EXPECT_EQ(j.size(), keys.size());
  for (const std::string& key : keys) EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j.at("save_dir"), "results/self_touch");
  EXPECT_EQ(j.at("behavior"), "self_touch");
  EXPECT_EQ(j.at("scene"), "crib");
  EXPECT_EQ(j.at("max_episode_steps"), 1000);
  EXPECT_EQ(j.at("touch_scale"), 1.0);
  EXPECT_EQ(j.at("touch_function"), "force_vector");
  EXPECT_EQ(j.at("touch_response"), "spread_linear");
  EXPECT_EQ(j.at("actuation_model"), "spring_damper");
  EXPECT_EQ(j.at("vision_active"), false);
  EXPECT_EQ(j.at("act_eyes"), false);
  EXPECT_EQ(j.at("lock_feet"), true);
  EXPECT_EQ(j.at("touch_eyes"), false);
  EXPECT_EQ(j.at("hand_regard_half_angle"), 15.0);
  EXPECT_TRUE(j.at("max_episode_steps").is_number_integer());
  EXPECT_TRUE(j.at("lock_feet").is_boolean());
}

}  // namespace
}  // namespace cradle
