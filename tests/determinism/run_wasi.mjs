// Runs a wasm32-wasip1 program under Node.js's WASI (`node:wasi`): the cargo runner for that
// target in `cargo xtask determinism`. Usage: node run_wasi.mjs PROGRAM.wasm [ARGS...]. Every
// argument that names an existing directory is preopened at the same path, so the program can
// write there; the program's exit code becomes this process's.
import { readFile } from "node:fs/promises";
import { existsSync, statSync } from "node:fs";
import { argv, env, exit } from "node:process";
import { WASI } from "node:wasi";

const [program, ...args] = argv.slice(2);
const preopens = {};
for (const a of args) {
  if (existsSync(a) && statSync(a).isDirectory()) preopens[a] = a;
}
const wasi = new WASI({ version: "preview1", args: [program, ...args], env, preopens, returnOnExit: true });
const module = await WebAssembly.compile(await readFile(program));
const instance = await WebAssembly.instantiate(module, { wasi_snapshot_preview1: wasi.wasiImport });
exit(wasi.start(instance));
