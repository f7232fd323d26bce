// Runs a wasm32-wasip1 binary (a test harness, say) under Node's WASI, with this process's
// arguments and environment and the file system at `/`: the cargo runner for wasm32-wasip1
// (`.cargo/config.toml`). Exits with the program's exit code.
import { readFile } from 'node:fs/promises';
import { WASI } from 'node:wasi';
import { argv, env, exit } from 'node:process';

const [, , wasm, ...args] = argv;
const wasi = new WASI({
  version: 'preview1',
  args: [wasm, ...args],
  env,
  preopens: { '/': '/' },
  returnOnExit: true,
});
const module = await WebAssembly.compile(await readFile(wasm));
const instance = await WebAssembly.instantiate(module, wasi.getImportObject());
exit(wasi.start(instance));
