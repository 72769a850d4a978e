#pragma once
// The version of every JSON document tomomap writes (docs/json.md): `match
// --json`, transforms.json, status.json and eval's rows.jsonl. It goes up when
// a field changes meaning or goes away; a new field does not raise it.
namespace tomomap {

constexpr int kJsonSchemaVersion = 6;

}  // namespace tomomap
