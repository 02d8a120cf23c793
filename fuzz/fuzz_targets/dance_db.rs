//! Fuzz target: the dance database and manifest readers (`Database::load`,
//! `Manifest::load`), on the input written to a file. Neither may panic; a database they
//! accept passes `Database::validate` and reads back the same after `to_json`; a manifest
//! accepted passes `Manifest::check`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use marionette::choreo::{Database, Manifest};

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("marionette-fuzz-db-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let db_path = dir.join("db.json");
    std::fs::write(&db_path, data).unwrap();
    if let Ok(db) = Database::load(&db_path) {
        db.validate().expect("a database read is valid");
        std::fs::write(&db_path, db.to_json()).unwrap();
        let again = Database::load(&db_path).expect("a database written reads back");
        assert_eq!(
            serde_json::to_string(&again).unwrap(),
            serde_json::to_string(&db).unwrap()
        );
    }
    let m_path = dir.join("manifest.ron");
    std::fs::write(&m_path, data).unwrap();
    if let Ok(m) = Manifest::load(&m_path) {
        assert!(!m.clips.is_empty());
        m.check().expect("a manifest read passes its check");
    }
});
