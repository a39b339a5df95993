//! Python 3 with a module a test drives.

use std::process::Command;

/// Python 3 with `module` importable, `package` (a pip requirement, such as
/// `eclipse-zenoh==1.10.2`) installed with pip where it is missing; the program to run,
/// `python3`.
///
/// # Panics
///
/// If `python3` does not run, if pip cannot install `package`, or if `module` cannot be
/// imported once `package` is installed; the message names `python3` or `package`.
pub fn python_with(module: &str, package: &str) -> &'static str {
    let importable = || {
        Command::new("python3")
            .args(["-c", &format!("import {module}")])
            .status()
            .is_ok_and(|status| status.success())
    };
    if !importable() {
        let installed = Command::new("python3")
            .args(["-m", "pip", "install", "--quiet", package])
            .status()
            .expect("python3 runs");
        assert!(installed.success(), "pip could not install {package}");
        assert!(
            importable(),
            "{package} installed, yet `import {module}` fails"
        );
    }
    "python3"
}
