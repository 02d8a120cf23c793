//! The stateful edit of a dance that a server holds (the paper's editing interface, §3.3): a
//! song's bars, the segment database, the pins (bar → segment the user set), per bar the search
//! state of eqs. (1)–(4) ([`BarSearch`]: the round k, S_n, L_l, the candidates shown), and
//! undo/redo of pin changes; [`Edit::generate`] fills every unpinned bar through the pins by the
//! minimum-cost path ([`super::fill`], Dijkstra over a transition table built once per edit).
//!
//! Undo and redo cover the pins only, the dance's content: a search round, a like and
//! [`Edit::start_over`] change what the user is shown, not the dance, and are not undone (the
//! likes survive a start over, so nothing the user chose is lost by it).
//! [`Edit::set_search_params`] changes τ_0 and the decay for every bar's next rounds (the
//! editor's "explore ↔ follow my likes").
//!
//! Everything but the database is an [`EditState`] (serde), so a server can save an edit with
//! its scene and restore it with [`Edit::from_state`]; every method checks its bar and segment
//! indices and answers bad ones with a typed [`EditError`], never a panic. An `Edit` is `Send +
//! Sync` (the database and its search index are shared behind `Arc`s), so a server can keep
//! one behind a `Mutex` for several tabs.

use std::collections::BTreeMap;
use std::sync::{Arc, OnceLock};

use serde::{Deserialize, Serialize};

use super::database::Database;
use super::fill::{Fill, FillError, FillParams, fill_with_table};
use super::music::Bar;
use super::relevance::music_intensity;
use super::search::{BarSearch, SearchError, SearchIndex, SearchParams};
use super::transition::{TransitionError, TransitionTable};

/// Why an edit action was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EditError {
    /// A song with no bar.
    #[error("the song has no bar to edit")]
    NoBars,
    /// A database with no segment.
    #[error("the dance database has no segment")]
    EmptyDatabase,
    /// A bar whose RMS is not a level.
    #[error("bar {bar}: its RMS level must be a number of dB (−∞ for silence), found {rms_db}")]
    BarLevel {
        /// The bar.
        bar: usize,
        /// Its level.
        rms_db: f64,
    },
    /// A bar index past the song's end.
    #[error("bar {bar} is past the song's end ({bars} bars, 0 to {})", bars - 1)]
    NoSuchBar {
        /// The index given.
        bar: usize,
        /// Bars in the song.
        bars: usize,
    },
    /// A segment index past the database's end.
    #[error("segment {segment} is not in the database ({segments} segments)")]
    NoSuchSegment {
        /// The index given.
        segment: usize,
        /// Segments in the database.
        segments: usize,
    },
    /// A like for a segment that was never shown for the bar.
    #[error("bar {bar}: segment {segment} was never shown as a candidate for this bar")]
    NotShown {
        /// The bar.
        bar: usize,
        /// The segment.
        segment: usize,
    },
    /// Unpinning a bar that has no pin.
    #[error("bar {bar} has no pin to remove")]
    NotPinned {
        /// The bar.
        bar: usize,
    },
    /// Undo with no pin change left to undo.
    #[error("nothing to undo")]
    NothingToUndo,
    /// Redo with no undone change.
    #[error("nothing to redo")]
    NothingToRedo,
    /// Every segment of the database has been shown for the bar ([`Edit::start_over`] shows
    /// them again).
    #[error(
        "bar {bar}: all {segments} segments have been shown; no new candidate is left (start \
         the bar's search over to see them again)"
    )]
    Exhausted {
        /// The bar.
        bar: usize,
        /// Segments in the database.
        segments: usize,
    },
    /// A saved state that does not fit the song or the database.
    #[error("edit state: {message}")]
    State {
        /// What does not fit.
        message: String,
    },
    /// The search itself (parameters).
    #[error(transparent)]
    Search(#[from] SearchError),
    /// The database's transition table (link weights, boundary data).
    #[error(transparent)]
    Transition(#[from] TransitionError),
    /// Filling the unpinned bars.
    #[error(transparent)]
    Fill(#[from] FillError),
}

/// One change of a bar's pin (for undo/redo): the segment pinned before and after (`None`:
/// unpinned).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PinChange {
    /// The bar.
    pub bar: usize,
    /// Its pin before the change.
    pub before: Option<usize>,
    /// Its pin after the change.
    pub after: Option<usize>,
}

/// Everything of an edit but the database (serde): what a server saves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EditState {
    /// The song's bars (span and RMS).
    pub bars: Vec<Bar>,
    /// The search parameters.
    pub search: SearchParams,
    /// The fill parameters of [`Edit::generate`].
    pub fill: FillParams,
    /// Pins: bar → segment index in the database.
    pub pins: BTreeMap<usize, usize>,
    /// The search state of every bar (one per bar).
    pub searches: Vec<BarSearch>,
    /// Pin changes that [`Edit::undo`] undoes, oldest first.
    pub undo: Vec<PinChange>,
    /// Undone changes that [`Edit::redo`] redoes, most recently undone last.
    pub redo: Vec<PinChange>,
}

/// `bar` checked against a song of `bars` bars.
fn bar_in(bar: usize, bars: usize) -> Result<(), EditError> {
    if bar < bars {
        Ok(())
    } else {
        Err(EditError::NoSuchBar { bar, bars })
    }
}

/// `segment` checked against a database of `segments` segments.
fn segment_in(segment: usize, segments: usize) -> Result<(), EditError> {
    if segment < segments {
        Ok(())
    } else {
        Err(EditError::NoSuchSegment { segment, segments })
    }
}

/// The edit of one dance (module docs).
#[derive(Debug, Clone)]
pub struct Edit {
    db: Arc<Database>,
    index: Arc<SearchIndex>,
    music: Vec<f64>,
    state: EditState,
    table: OnceLock<Arc<TransitionTable>>,
}

impl Edit {
    /// A fresh edit of the song `bars` over `db`: nothing pinned, no bar searched yet.
    pub fn new(
        db: Arc<Database>,
        bars: Vec<Bar>,
        search: SearchParams,
        fill: FillParams,
    ) -> Result<Edit, EditError> {
        let searches = vec![BarSearch::new(); bars.len()];
        Edit::from_state(
            db,
            EditState {
                bars,
                search,
                fill,
                pins: BTreeMap::new(),
                searches,
                undo: vec![],
                redo: vec![],
            },
        )
    }

    /// An edit restored from a saved state over `db`, after checking that every bar, pin,
    /// shown or liked segment and undo entry fits the song and the database.
    pub fn from_state(db: Arc<Database>, state: EditState) -> Result<Edit, EditError> {
        let index = Arc::new(SearchIndex::new(&db));
        Edit::with_index(db, index, state)
    }

    /// [`Edit::from_state`] with a search index already packed for `db` (a server editing
    /// several songs over one database shares it).
    pub fn with_index(
        db: Arc<Database>,
        index: Arc<SearchIndex>,
        state: EditState,
    ) -> Result<Edit, EditError> {
        state.search.check()?;
        if state.bars.is_empty() {
            return Err(EditError::NoBars);
        }
        if db.segments.is_empty() {
            return Err(EditError::EmptyDatabase);
        }
        if index.len() != db.segments.len() {
            return Err(EditError::State {
                message: format!(
                    "the search index has {} segments, the database {}",
                    index.len(),
                    db.segments.len()
                ),
            });
        }
        if let Some((bar, b)) = state
            .bars
            .iter()
            .enumerate()
            .find(|(_, b)| b.rms_db.is_nan() || b.rms_db == f64::INFINITY)
        {
            return Err(EditError::BarLevel {
                bar,
                rms_db: b.rms_db,
            });
        }
        let (bars, segments) = (state.bars.len(), db.segments.len());
        if state.searches.len() != bars {
            return Err(EditError::State {
                message: format!(
                    "{} bar searches for {bars} bars (one per bar expected)",
                    state.searches.len()
                ),
            });
        }
        let check_bar = |bar| bar_in(bar, bars);
        let check_segment = |segment| segment_in(segment, segments);
        for (&bar, &seg) in &state.pins {
            check_bar(bar)?;
            check_segment(seg)?;
        }
        for s in &state.searches {
            for &seg in s.shown.iter().chain(&s.liked).chain(&s.current) {
                check_segment(seg)?;
            }
        }
        for c in state.undo.iter().chain(&state.redo) {
            check_bar(c.bar)?;
            for seg in c.before.iter().chain(&c.after) {
                check_segment(*seg)?;
            }
        }
        let music = music_intensity(&state.bars);
        Ok(Edit {
            db,
            index,
            music,
            state,
            table: OnceLock::new(),
        })
    }

    /// The state to save (everything but the database).
    pub fn state(&self) -> &EditState {
        &self.state
    }

    /// The database.
    pub fn database(&self) -> &Arc<Database> {
        &self.db
    }

    /// The search index of the database.
    pub fn index(&self) -> &Arc<SearchIndex> {
        &self.index
    }

    /// The song's bars.
    pub fn bars(&self) -> &[Bar] {
        &self.state.bars
    }

    /// Each bar's normalised music intensity (percentile rank of its RMS among the song's bars).
    pub fn music_intensity(&self) -> &[f64] {
        &self.music
    }

    /// The pins: bar → segment.
    pub fn pins(&self) -> &BTreeMap<usize, usize> {
        &self.state.pins
    }

    fn check_bar(&self, bar: usize) -> Result<(), EditError> {
        bar_in(bar, self.state.bars.len())
    }

    fn check_segment(&self, segment: usize) -> Result<(), EditError> {
        segment_in(segment, self.db.segments.len())
    }

    /// The search state of `bar`.
    pub fn bar_search(&self, bar: usize) -> Result<&BarSearch, EditError> {
        self.check_bar(bar)?;
        Ok(&self.state.searches[bar])
    }

    /// The candidates of `bar`'s last search round (empty before its first).
    pub fn candidates(&self, bar: usize) -> Result<&[usize], EditError> {
        Ok(&self.bar_search(bar)?.current)
    }

    /// The next search round for `bar` (eq. 1 with its τ_k, S_n and L_l): its new candidates,
    /// fewer than [`SearchParams::candidates`] when the database runs short, and
    /// [`EditError::Exhausted`] once every segment has been shown for the bar.
    pub fn search(&mut self, bar: usize) -> Result<Vec<usize>, EditError> {
        self.check_bar(bar)?;
        let picks = self.index.round(
            self.music[bar],
            &mut self.state.searches[bar],
            &self.state.search,
        )?;
        if picks.is_empty() {
            return Err(EditError::Exhausted {
                bar,
                segments: self.db.segments.len(),
            });
        }
        Ok(picks)
    }

    /// Likes (`liked` true: into L_l) or unlikes a segment shown for `bar`.
    pub fn like(&mut self, bar: usize, segment: usize, liked: bool) -> Result<(), EditError> {
        self.check_bar(bar)?;
        self.check_segment(segment)?;
        let s = &mut self.state.searches[bar];
        if !s.shown.contains(&segment) {
            return Err(EditError::NotShown { bar, segment });
        }
        s.like(segment, liked);
        Ok(())
    }

    /// Starts `bar`'s search over ([`BarSearch::start_over`]): round 0, nothing shown but the
    /// likes, which are kept. Not an undoable change (module docs).
    pub fn start_over(&mut self, bar: usize) -> Result<(), EditError> {
        self.check_bar(bar)?;
        self.state.searches[bar].start_over();
        Ok(())
    }

    /// The search parameters.
    pub fn search_params(&self) -> &SearchParams {
        &self.state.search
    }

    /// Replaces the search parameters (after checking them): every bar's next round runs with
    /// them, at τ_k = τ_0·decay^k of its own round k.
    pub fn set_search_params(&mut self, p: SearchParams) -> Result<(), EditError> {
        p.check()?;
        self.state.search = p;
        Ok(())
    }

    /// Records and applies a pin change (none when it changes nothing).
    fn change(&mut self, bar: usize, after: Option<usize>) {
        let before = self.state.pins.get(&bar).copied();
        if before == after {
            return;
        }
        self.apply(bar, after);
        self.state.undo.push(PinChange { bar, before, after });
        self.state.redo.clear();
    }

    fn apply(&mut self, bar: usize, to: Option<usize>) {
        match to {
            Some(s) => self.state.pins.insert(bar, s),
            None => self.state.pins.remove(&bar),
        };
    }

    /// Pins `segment` to `bar` (the paper's Set), replacing any pin it had.
    pub fn set(&mut self, bar: usize, segment: usize) -> Result<(), EditError> {
        self.check_bar(bar)?;
        self.check_segment(segment)?;
        self.change(bar, Some(segment));
        Ok(())
    }

    /// Removes `bar`'s pin.
    pub fn unpin(&mut self, bar: usize) -> Result<(), EditError> {
        self.check_bar(bar)?;
        if !self.state.pins.contains_key(&bar) {
            return Err(EditError::NotPinned { bar });
        }
        self.change(bar, None);
        Ok(())
    }

    /// Undoes the last pin change and returns it.
    pub fn undo(&mut self) -> Result<PinChange, EditError> {
        let c = self.state.undo.pop().ok_or(EditError::NothingToUndo)?;
        self.apply(c.bar, c.before);
        self.state.redo.push(c);
        Ok(c)
    }

    /// The paper's Generate: every unpinned bar filled through the pins by the minimum-cost
    /// path (the exact dynamic programme of [`super::fill::fill`], which gives the same path
    /// as Dijkstra and is many times faster on a large database, on the database's
    /// transition table, built at the first call and kept). The pins are honoured exactly.
    pub fn generate(&self) -> Result<Fill, EditError> {
        let table = match self.table.get() {
            Some(t) => t.clone(),
            None => {
                let t = Arc::new(TransitionTable::new(&self.db, &self.state.fill.transition)?);
                self.table.get_or_init(|| t).clone()
            }
        };
        Ok(fill_with_table(
            &self.db,
            &table,
            &self.music,
            &self.state.pins,
            &self.state.fill,
        )?)
    }

    /// Redoes the last undone pin change and returns it.
    pub fn redo(&mut self) -> Result<PinChange, EditError> {
        let c = self.state.redo.pop().ok_or(EditError::NothingToRedo)?;
        self.apply(c.bar, c.after);
        self.state.undo.push(c);
        Ok(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::choreo::search::tests::random_db;

    fn bars(n: usize) -> Vec<Bar> {
        (0..n)
            .map(|k| {
                let rms_db = -30.0 + 3.0 * (k % 7) as f64;
                Bar {
                    start_s: 2.0 * k as f64,
                    end_s: 2.0 * (k + 1) as f64,
                    rms: 10f64.powf(rms_db / 20.0),
                    rms_db,
                }
            })
            .collect()
    }

    fn edit() -> Edit {
        Edit::new(
            Arc::new(random_db(40, 9)),
            bars(8),
            SearchParams::default(),
            FillParams::default(),
        )
        .unwrap()
    }

    #[test]
    fn an_edit_is_send_and_sync() {
        fn check<T: Send + Sync>() {}
        check::<Edit>();
        check::<std::sync::Mutex<Edit>>();
    }

    #[test]
    fn search_like_set_undo_redo_and_restore() {
        let mut e = edit();
        assert!(e.candidates(3).unwrap().is_empty());
        let first = e.search(3).unwrap();
        assert_eq!(first.len(), 6);
        assert_eq!(e.candidates(3).unwrap(), &first[..]);
        e.like(3, first[1], true).unwrap();
        e.like(3, first[2], true).unwrap();
        e.like(3, first[2], false).unwrap();
        assert_eq!(e.bar_search(3).unwrap().liked, vec![first[1]]);
        let second = e.search(3).unwrap();
        assert!(second.iter().all(|s| !first.contains(s)));
        assert_eq!(e.bar_search(3).unwrap().round, 2);
        assert_eq!(e.bar_search(2).unwrap().round, 0);

        e.set(3, second[0]).unwrap();
        e.set(5, 7).unwrap();
        e.set(5, 7).unwrap(); // no change, no undo entry
        e.set(5, 9).unwrap();
        e.unpin(3).unwrap();
        assert_eq!(e.pins(), &BTreeMap::from([(5, 9)]));
        assert_eq!(e.state().undo.len(), 4);
        assert_eq!(e.undo().unwrap().bar, 3);
        assert_eq!(e.undo().unwrap().after, Some(9));
        assert_eq!(e.pins(), &BTreeMap::from([(3, second[0]), (5, 7)]));
        e.redo().unwrap();
        assert_eq!(e.pins(), &BTreeMap::from([(3, second[0]), (5, 9)]));
        // A new change forgets what was undone.
        e.set(0, 1).unwrap();
        assert_eq!(e.redo(), Err(EditError::NothingToRedo));

        // Saved and restored, the same edit, and the same next round.
        let json = serde_json::to_string(e.state()).unwrap();
        let state: EditState = serde_json::from_str(&json).unwrap();
        let mut back = Edit::from_state(e.database().clone(), state).unwrap();
        assert_eq!(back.state(), e.state());
        assert_eq!(back.search(3).unwrap(), e.search(3).unwrap());
    }

    #[test]
    fn start_over_keeps_the_likes_reachable_and_tau0_is_set_for_the_next_rounds() {
        let mut e = edit();
        let first = e.search(4).unwrap();
        e.like(4, first[0], true).unwrap();
        e.set(4, first[1]).unwrap();
        while e.search(4).is_ok() {}
        assert_eq!(e.bar_search(4).unwrap().shown.len(), 40);
        assert_eq!(
            e.search(4),
            Err(EditError::Exhausted {
                bar: 4,
                segments: 40
            })
        );
        e.start_over(4).unwrap();
        let s = e.bar_search(4).unwrap();
        assert_eq!((s.round, s.shown.clone()), (0, vec![first[0]]));
        assert!(e.candidates(4).unwrap().is_empty());
        // The like survives (it can be unliked and liked again), and the pin and its undo are
        // untouched; the new rounds show the 39 others.
        assert_eq!(s.liked, vec![first[0]]);
        assert_eq!(e.pins(), &BTreeMap::from([(4, first[1])]));
        assert_eq!(e.state().undo.len(), 1);
        e.like(4, first[0], false).unwrap();
        e.like(4, first[0], true).unwrap();
        let mut again = vec![];
        while let Ok(c) = e.search(4) {
            again.extend(c);
        }
        assert_eq!(again.len(), 39);
        assert!(!again.contains(&first[0]));
        assert_eq!(
            e.start_over(8),
            Err(EditError::NoSuchBar { bar: 8, bars: 8 })
        );

        // τ_0 for the next rounds: checked, and used at the bar's own round.
        let bad = SearchParams {
            tau0: 2.0,
            ..SearchParams::default()
        };
        assert!(matches!(
            e.set_search_params(bad),
            Err(EditError::Search(SearchError::Params { .. }))
        ));
        assert_eq!(e.search_params().tau0, 1.0);
        let follow = SearchParams {
            tau0: 0.2,
            ..SearchParams::default()
        };
        e.set_search_params(follow.clone()).unwrap();
        assert_eq!(e.search_params(), &follow);
        let k = e.bar_search(4).unwrap().round;
        assert_eq!(k, 7, "39 segments in rounds of six");
        assert!((e.search_params().tau(k) - 0.2 * 0.95f64.powi(7)).abs() < 1e-15);
    }

    #[test]
    fn bad_indices_give_typed_errors() {
        let mut e = edit();
        let no_bar = EditError::NoSuchBar { bar: 8, bars: 8 };
        assert_eq!(e.search(8), Err(no_bar.clone()));
        assert_eq!(e.set(8, 0), Err(no_bar.clone()));
        assert_eq!(e.unpin(8), Err(no_bar.clone()));
        assert_eq!(e.candidates(8).map(|c| c.len()), Err(no_bar.clone()));
        assert_eq!(e.like(8, 0, true), Err(no_bar));
        let no_seg = EditError::NoSuchSegment {
            segment: 40,
            segments: 40,
        };
        assert_eq!(e.set(0, 40), Err(no_seg.clone()));
        assert_eq!(e.like(0, 40, true), Err(no_seg));
        assert_eq!(
            e.like(0, 3, true),
            Err(EditError::NotShown { bar: 0, segment: 3 })
        );
        assert_eq!(e.unpin(0), Err(EditError::NotPinned { bar: 0 }));
        assert_eq!(e.undo(), Err(EditError::NothingToUndo));
        // This database has no boundary data: Generate says so.
        assert!(matches!(e.generate(), Err(EditError::Transition(_))));
        assert!(e.search(8).unwrap_err().to_string().contains("0 to 7"));
    }

    #[test]
    fn searching_a_bar_until_nothing_is_left_says_it_is_exhausted() {
        let mut e = edit();
        // 40 segments = 6 × 6 + 4.
        for _ in 0..6 {
            assert_eq!(e.search(1).unwrap().len(), 6);
        }
        assert_eq!(e.search(1).unwrap().len(), 4);
        assert_eq!(
            e.search(1),
            Err(EditError::Exhausted {
                bar: 1,
                segments: 40
            })
        );
    }

    #[test]
    fn construction_and_restoring_check_their_input() {
        let db = Arc::new(random_db(40, 9));
        assert_eq!(
            Edit::new(
                db.clone(),
                vec![],
                SearchParams::default(),
                FillParams::default()
            )
            .unwrap_err(),
            EditError::NoBars
        );
        assert_eq!(
            Edit::new(
                Arc::new(random_db(0, 1)),
                bars(2),
                SearchParams::default(),
                FillParams::default()
            )
            .unwrap_err(),
            EditError::EmptyDatabase
        );
        let mut nan = bars(3);
        nan[1].rms_db = f64::NAN;
        assert!(matches!(
            Edit::new(
                db.clone(),
                nan,
                SearchParams::default(),
                FillParams::default()
            ),
            Err(EditError::BarLevel { bar: 1, .. })
        ));
        let mut state = edit().state().clone();
        state.pins.insert(2, 99);
        assert!(matches!(
            Edit::from_state(db.clone(), state),
            Err(EditError::NoSuchSegment { segment: 99, .. })
        ));
        let mut state = edit().state().clone();
        state.searches.pop();
        assert!(matches!(
            Edit::from_state(db, state),
            Err(EditError::State { .. })
        ));
    }
}
