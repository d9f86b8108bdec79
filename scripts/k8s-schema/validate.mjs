// Validates Kubernetes documents against the API's schemas (kubernetes-models, package.json):
// field types, formats, enums and required fields. Unknown fields pass, as the models' schemas
// allow them; scripts/check-deploy-manifests.sh checks the fields the deployment relies on.
//
//   node validate.mjs DOCUMENTS.json   (a JSON array of {"where": TEXT, "document": OBJECT})
//
// Prints one line per invalid document and exits 1 if there is any.
import { readFileSync } from "node:fs";
import { createRequire } from "node:module";

const require = createRequire(import.meta.url);
const documents = JSON.parse(readFileSync(process.argv[2], "utf8"));
let invalid = 0;
for (const { where, document } of documents) {
  // v1 is the core group: kubernetes-models/v1/Service; the others kubernetes-models/apps/v1/...
  const path = `kubernetes-models/${document.apiVersion}/${document.kind}`;
  let Model;
  try {
    Model = require(path)[document.kind];
  } catch (error) {
    console.log(`${where}: no schema for ${document.apiVersion} ${document.kind}`);
    invalid++;
    continue;
  }
  try {
    new Model(document).validate();
  } catch (error) {
    console.log(`${where}: ${error.message.replace(/\s+/g, " ")}`);
    invalid++;
  }
}
process.exit(invalid === 0 ? 0 : 1);
