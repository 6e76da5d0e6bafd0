// ofn_bus_keygen: makes the keyring of an authenticated deployment, a key
// pair for every role of a publish policy and a copy of the policy, in one
// directory. Every host gets policy.yaml and all *.pub files, and only its
// own <role>.key.
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <iostream>

#include <CLI/CLI.hpp>

#include "ofn/bus_auth/authenticator.hpp"
#include "ofn/common/service_main.hpp"

int main(int argc, char** argv) {
  std::string policy_path = "config/bus_policy.yaml";
  std::string out;
  bool force = false;
  ofn::CommandLine app{
      "ofn_bus_keygen",
      "Makes the keyring of an authenticated bus: an Ed25519 key pair per role of the "
      "publish policy, and the policy, in one directory (docs/DEPLOYMENT.md).\n"
      "Give each host policy.yaml, every *.pub and only its own <role>.key; start its "
      "services with --bus-keys DIR --bus-role ROLE (deploy/launch.py --bus-keys DIR)."};
  app.add_option("--policy", policy_path, "publish policy (YAML)")->check(CLI::ExistingFile);
  app.add_option("--out", out, "keyring directory to make")->required();
  app.add_flag("--force", force, "replace the keys of an existing keyring");
  if (const auto code = ofn::parse_command_line(app, argc, argv)) return *code;

  return ofn::guarded_main("ofn_bus_keygen", [&] {
    namespace fs = std::filesystem;
    // The default is the repository's policy, relative to the working
    // directory: said so when it is not there.
    if (!std::filesystem::exists(policy_path))
      throw std::invalid_argument("cannot read publish policy '" + policy_path +
                                  "' (run from the repository root, or pass --policy FILE)");
    const auto policy = ofn::bus_auth::PublishPolicy::load(policy_path);
    const fs::path dir(out);
    if (fs::exists(dir / "policy.yaml") && !force)
      throw std::invalid_argument("'" + out +
                                  "' already holds a keyring; --force replaces its keys (every "
                                  "host then needs the new ones)");
    fs::create_directories(dir);
    // The directory holds secret keys: only its owner may list it.
    fs::permissions(dir, fs::perms::owner_all, fs::perm_options::replace);
    for (const auto& role : policy.roles()) {
      const auto pair = ofn::bus_auth::generate_key_pair();
      ofn::bus_auth::write_public_key((dir / (role + ".pub")).string(), pair.public_key);
      ofn::bus_auth::write_secret_key((dir / (role + ".key")).string(), pair.secret_key);
      std::cout << "role " << role << ": " << (dir / (role + ".pub")).string() << ", "
                << (dir / (role + ".key")).string() << "\n";
    }
    fs::copy_file(policy_path, dir / "policy.yaml", fs::copy_options::overwrite_existing);
    std::cout << "keyring in " << out << " (policy " << policy_path << ")\n";
    return 0;
  });
}
