//! Every kept fuzz input (`corpus/TARGET/`) and every input that once failed
//! (`regressions/TARGET/`) through its target, in the ordinary test build: a fixed bug stays
//! fixed without the fuzzer.

use std::path::Path;

#[test]
fn every_kept_input_passes_its_target() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut ran = 0;
    for (name, target) in dupin_fuzz::TARGETS {
        assert!(
            root.join("fuzz_targets")
                .join(format!("{name}.rs"))
                .is_file(),
            "the target {name} has no fuzz binary"
        );
        let mut seeds = 0;
        for folder in ["corpus", "regressions"] {
            let Ok(dir) = std::fs::read_dir(root.join(folder).join(name)) else {
                continue;
            };
            let mut files: Vec<_> = dir.map(|e| e.unwrap().path()).collect();
            files.sort();
            for file in files {
                let data = std::fs::read(&file).unwrap();
                target(&data);
                seeds += 1;
            }
        }
        assert!(seeds > 0, "the target {name} has no kept inputs");
        ran += seeds;
    }
    println!("{ran} kept inputs passed");
}
