// Runs the Khronos glTF validator (the npm package gltf-validator) on one
// .glb or .gltf file and prints its report as JSON on stdout.
//
//   node tests/gltf/validate.mjs FILE [PREFIX]
//
// PREFIX is the folder given to `npm install --prefix` (default:
// $GLTF_VALIDATOR_PREFIX, else target/gltf-validator beside this repository's
// Cargo.toml). Exit status: 0 when a report was printed (whatever it found),
// 3 when the package is not installed there, 1 on any other failure.
import { createRequire } from "node:module";
import { readFile } from "node:fs/promises";
import path from "node:path";
import { fileURLToPath } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
const file = process.argv[2];
const prefix =
  process.argv[3] ||
  process.env.GLTF_VALIDATOR_PREFIX ||
  path.join(here, "..", "..", "target", "gltf-validator");
if (!file) {
  console.error("usage: node tests/gltf/validate.mjs FILE [PREFIX]");
  process.exit(1);
}

let validator;
try {
  validator = createRequire(path.join(path.resolve(prefix), "package.json"))(
    "gltf-validator",
  );
} catch (error) {
  console.error(`gltf-validator is not installed under ${prefix}: ${error.message}`);
  process.exit(3);
}

try {
  const bytes = await readFile(file);
  const report = await validator.validateBytes(new Uint8Array(bytes), {
    uri: path.basename(file),
    maxIssues: 100,
    // Only files beside the glTF (pmvc embeds its buffer, so none are asked for).
    externalResourceFunction: (uri) =>
      readFile(path.join(path.dirname(file), decodeURIComponent(uri))).then(
        (data) => new Uint8Array(data),
      ),
  });
  console.log(JSON.stringify(report, null, 2));
} catch (error) {
  console.error(`validation failed: ${error?.message ?? error}`);
  process.exit(1);
}
