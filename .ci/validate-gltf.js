// Validate binary glTF files with the Khronos glTF Validator (npm package
// gltf-validator, installed by .ci/run into .ci/node). Prints each file's
// issue counts and every message; exits 1 if any file has an error.
// Usage: node .ci/validate-gltf.js FILE.glb...
"use strict";
const fs = require("fs");
const path = require("path");
const validator = require(path.join(__dirname, "node", "node_modules", "gltf-validator"));

async function main(files) {
    if (files.length === 0) {
        console.error("usage: node .ci/validate-gltf.js FILE.glb...");
        return 2;
    }
    let failed = false;
    for (const file of files) {
        const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
            uri: path.basename(file),
            maxIssues: 0,
        });
        const i = report.issues;
        console.log(
            `${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints`
        );
        for (const m of i.messages) {
            const severity = ["error", "warning", "info", "hint"][m.severity] || m.severity;
            console.log(`  ${severity} ${m.code} ${m.pointer || ""}: ${m.message}`);
        }
        if (i.numErrors > 0) {
            failed = true;
        }
    }
    return failed ? 1 : 0;
}

main(process.argv.slice(2)).then(
    (code) => process.exit(code),
    (e) => {
        console.error(e);
        process.exit(1);
    }
);
