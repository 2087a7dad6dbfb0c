// What a web test does when something it needs is missing (the browser, playwright-core in
// node_modules, the server binary): exit 77, which ctest reports as skipped, or under CI=true
// exit 1, so that a broken install on the CI machine fails instead of passing as skipped.
export function skip(why) {
  if (process.env.CI === 'true') {
    console.log(`FAIL: ${why} (CI=true: a missing test dependency is a broken install, not a skip)`);
    process.exit(1);
  }
  console.log(`SKIP: ${why}`);
  process.exit(77);
}
