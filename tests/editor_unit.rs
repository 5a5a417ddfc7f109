//! An editor panel is a unit (issue 55, item 3): the editor's state is a few parts that own
//! their own state, not one struct that takes in every feature, and a job hands its own typed
//! result to the function its starter names, not a variant of one enum that one match reads.
//! A tool's options are its own type (item 5), never a string id.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

#[expect(
    dead_code,
    reason = "this test reads files, not the ARCHITECTURE.md lists"
)]
mod product_sources;

use product_sources::root;

/// The most fields `EditorState` may keep (the bound).
const MOST_FIELDS: usize = 16;

/// The most files that may hold `impl EditorState` (the bound): its accessors, the
/// one place asks are carried out, the jobs' machinery and the input.
const MOST_IMPL_FILES: usize = 4;

/// The fields of `struct NAME` in `source`: its lines at the struct's indentation plus four
/// that declare a field (`name: Type,`).
fn fields(source: &str, name: &str) -> Option<Vec<String>> {
    let start = source.find(&format!("pub struct {name} {{"))?;
    let body = &source[start..];
    let end = body.find("\n}")?;
    Some(
        body[..end]
            .lines()
            .skip(1)
            .filter_map(|line| {
                let field = line.strip_prefix("    ")?;
                if field.starts_with(' ') || field.starts_with("//") || field.starts_with('#') {
                    return None;
                }
                let field = field.strip_prefix("pub ").unwrap_or(field);
                let (name, _) = field.split_once(':')?;
                Some(name.trim().to_string())
            })
            .collect(),
    )
}

/// `file:line` of every line of the Rust files under `dir` (from the root) that `matches`.
fn lines_where(dir: &str, matches: impl Fn(&str) -> bool) -> Vec<String> {
    let mut files = Vec::new();
    product_sources::files(&root().join(dir), "rs", &mut files);
    let mut found = Vec::new();
    for file in files {
        let text = std::fs::read_to_string(&file).expect("a source file");
        for (i, line) in text.lines().enumerate() {
            if matches(line) {
                found.push(format!("{}:{}", file.display(), i + 1));
            }
        }
    }
    found
}

#[test]
fn the_editor_state_keeps_at_most_sixteen_parts() {
    let lib = std::fs::read_to_string(root().join("crates/kapaint-editor/src/lib.rs"))
        .expect("the editor's lib.rs");
    let fields = fields(&lib, "EditorState").expect("EditorState in the editor's lib.rs");
    assert!(
        fields.len() <= MOST_FIELDS,
        "EditorState keeps {} fields (at most {MOST_FIELDS}): {fields:?}",
        fields.len()
    );
    assert!(fields.contains(&"doc".to_string()), "{fields:?}");
}

#[test]
fn jobs_report_through_their_own_types() {
    let found = lines_where("crates/kapaint-editor/src", |line| {
        line.contains("enum JobResult") || line.contains("JobResult::")
    });
    assert!(
        found.is_empty(),
        "one enum for every job's result (each job names its result type and the function \
         that takes it): {found:?}"
    );
}

#[test]
fn the_editor_state_is_changed_in_at_most_four_files() {
    let found = lines_where("crates/kapaint-editor/src", |line| {
        line.starts_with("impl EditorState")
    });
    let mut files: Vec<&str> = found
        .iter()
        .map(|at| at.rsplit_once(':').map_or(at.as_str(), |(file, _)| file))
        .collect();
    files.dedup();
    assert!(
        !files.is_empty() && files.len() <= MOST_IMPL_FILES,
        "impl EditorState in {} files (at most {MOST_IMPL_FILES}: a panel, a dialog or a job \
         is a view that reads the document and asks through a Desk): {files:?}",
        files.len()
    );
}

#[test]
fn finished_jobs_ask_through_a_desk() {
    let found = lines_where("crates/kapaint-editor/src", |line| {
        let code = line.split("//").next().unwrap_or("");
        code.contains("fn(&mut EditorState") || code.contains("FnOnce(&mut EditorState")
    });
    assert!(
        found.is_empty(),
        "a job that changes the editor itself when done (its done function reads the \
         document and asks through a Desk): {found:?}"
    );
}

#[test]
fn tool_options_are_typed_per_tool() {
    let found = lines_where("crates", |line| {
        let code = line.split("//").next().unwrap_or("");
        code.contains("OptionValue") || code.contains("fn set_option(&mut self, id: &str")
    });
    assert!(
        found.is_empty(),
        "a tool option set by a string id and an untyped value (each tool's options are its own \
         type inside OptionChange): {found:?}"
    );
}

#[test]
fn the_field_reader_reads_fields() {
    let source = "pub struct S {\n    /// doc\n    a: u32,\n    pub b: Option<(u8,\n        u8)>,\n    #[x]\n    c: bool,\n}\n";
    assert_eq!(
        fields(source, "S"),
        Some(vec!["a".into(), "b".into(), "c".into()])
    );
}
