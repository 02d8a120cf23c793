//! The automatic mapping on skeletons generated in code, one per naming convention (CMU cgspeed,
//! CMU acRNN, CMU/Vicon ASF names, Mixamo, HumanIK/MotionBuilder, 3ds Max Biped, Unreal
//! mannequin, Unity humanoid, SMPL, Bandai, OptiTrack Motive, Character Creator, Blender Rigify),
//! one with meaningless joint names and one mirrored (side words contradicting the geometry).
//! Every rig carries the same motion (the project's keyframed knee kick on humanoid24) under its
//! own names, hierarchy depth (spine and neck joints, zero-length helpers, twist bones, fingers,
//! eyes, a root at the floor) and rest pose (standing, T, A, or meaningless): every landmark is
//! found where the rig has it, left is left, and the feet of the mapped humanoid24 are within
//! 5 cm of the rig's. Non-humanoids are refused with a message naming what is missing.

use std::collections::BTreeMap;

use glam::{DQuat, DVec3};
use marionette::clips::KeyframeClip;
use marionette::humanoid::{Figure, FigureClip};
use marionette::mapping::{AutoMapping, Mapping, Synonyms, effector_errors, retarget};
use marionette::skeleton::{Clip, Joint, Skeleton, Transform};

/// The motion every rig carries.
fn motion() -> FigureClip {
    KeyframeClip::parse(
        include_str!("../../scenes/clips/knee_kick.ron"),
        "knee_kick.ron",
    )
    .unwrap()
    .to_figure_clip()
}

/// How an End Site is placed: none, at the part's far end, or on the joint (zero offset).
#[derive(Clone, Copy, PartialEq)]
enum End {
    None,
    Far,
    Zero,
}

/// The rest pose of a rig: the model's (standing, arms down), T, A, or arbitrary per link.
#[derive(Clone, Copy, PartialEq)]
enum Rest {
    Standing,
    T,
    A,
    Meaningless,
}

/// A rig convention. Names are templates: `{Side}` → Left/Right, `{S}` → L/R, `{s}` → l/r,
/// `{side}` → left/right.
#[derive(Clone)]
struct Rig {
    name: &'static str,
    root: Option<&'static str>,
    pelvis: &'static str,
    /// Biped: a spine joint on the pelvis, 5 cm up, from which legs and spine hang.
    pre_spine: Option<&'static str>,
    /// CC: a joint under the pelvis joint (zero length) carrying the legs.
    legs_under: Option<&'static str>,
    /// CMU: a zero-length joint at the pelvis before the spine.
    lower_back: Option<&'static str>,
    /// From the waist up; the last is the hub of arms and neck (unless `neck_hub`).
    spine: &'static [&'static str],
    neck: &'static [&'static str],
    /// CMU: the first neck joint sits on the hub (zero length).
    neck_zero: bool,
    /// Biped: the clavicles hang from the first neck joint.
    neck_hub: bool,
    head: &'static str,
    head_end: End,
    head_nub: Option<&'static str>,
    eyes: Option<&'static str>,
    clavicle: Option<&'static str>,
    /// CMU: the clavicle joint sits on the hub.
    clavicle_zero: bool,
    shoulder: &'static str,
    twist: Option<&'static str>,
    elbow: &'static str,
    wrist: &'static str,
    wrist_end: End,
    finger: Option<&'static str>,
    finger2: Option<&'static str>,
    thumb: Option<&'static str>,
    hip_helper: Option<&'static str>,
    buttock: Option<&'static str>,
    thigh: &'static str,
    thigh_twist: Option<&'static str>,
    knee: &'static str,
    foot: &'static str,
    foot_end: End,
    toe: Option<&'static str>,
    toe_end: End,
    rest: Rest,
    /// Side words swapped (names contradicting the geometry).
    mirrored: bool,
}

const BASE: Rig = Rig {
    name: "",
    root: None,
    pelvis: "Hips",
    pre_spine: None,
    legs_under: None,
    lower_back: None,
    spine: &["Spine"],
    neck: &["Neck"],
    neck_zero: false,
    neck_hub: false,
    head: "Head",
    head_end: End::Far,
    head_nub: None,
    eyes: None,
    clavicle: None,
    clavicle_zero: false,
    shoulder: "",
    twist: None,
    elbow: "",
    wrist: "",
    wrist_end: End::Far,
    finger: None,
    finger2: None,
    thumb: None,
    hip_helper: None,
    buttock: None,
    thigh: "",
    thigh_twist: None,
    knee: "",
    foot: "",
    foot_end: End::Far,
    toe: None,
    toe_end: End::Far,
    rest: Rest::T,
    mirrored: false,
};

fn rigs() -> Vec<Rig> {
    vec![
        Rig {
            name: "CMU cgspeed",
            lower_back: Some("LowerBack"),
            spine: &["Spine", "Spine1"],
            neck: &["Neck", "Neck1"],
            neck_zero: true,
            clavicle: Some("{Side}Shoulder"),
            clavicle_zero: true,
            shoulder: "{Side}Arm",
            elbow: "{Side}ForeArm",
            wrist: "{Side}Hand",
            finger: Some("{S}Fingers"),
            thumb: Some("{S}Thumb"),
            hip_helper: Some("{S}HipJoint"),
            thigh: "{Side}UpLeg",
            knee: "{Side}Leg",
            foot: "{Side}Foot",
            toe: Some("{Side}ToeBase"),
            ..BASE
        },
        Rig {
            name: "CMU acRNN",
            pelvis: "hip",
            spine: &["abdomen", "chest"],
            neck: &["neck"],
            head: "head",
            head_end: End::None,
            eyes: Some("{side}Eye"),
            clavicle: Some("{s}Collar"),
            shoulder: "{s}Shldr",
            elbow: "{s}ForeArm",
            wrist: "{s}Hand",
            finger: Some("{s}Mid1"),
            finger2: Some("{s}Mid2"),
            thumb: Some("{s}Thumb1"),
            buttock: Some("{s}Buttock"),
            thigh: "{s}Thigh",
            knee: "{s}Shin",
            foot: "{s}Foot",
            ..BASE
        },
        Rig {
            name: "CMU ASF / Vicon",
            pelvis: "root",
            spine: &["lowerback", "upperback", "thorax"],
            neck: &["lowerneck", "upperneck"],
            head: "head",
            clavicle: Some("{s}clavicle"),
            shoulder: "{s}humerus",
            elbow: "{s}radius",
            wrist: "{s}wrist",
            finger: Some("{s}hand"),
            thumb: Some("{s}thumb"),
            hip_helper: Some("{s}hipjoint"),
            thigh: "{s}femur",
            knee: "{s}tibia",
            foot: "{s}foot",
            toe: Some("{s}toes"),
            ..BASE
        },
        Rig {
            name: "Mixamo",
            pelvis: "mixamorig:Hips",
            spine: &["mixamorig:Spine", "mixamorig:Spine1", "mixamorig:Spine2"],
            neck: &["mixamorig:Neck"],
            head: "mixamorig:Head",
            head_end: End::None,
            head_nub: Some("mixamorig:HeadTop_End"),
            clavicle: Some("mixamorig:{Side}Shoulder"),
            shoulder: "mixamorig:{Side}Arm",
            elbow: "mixamorig:{Side}ForeArm",
            wrist: "mixamorig:{Side}Hand",
            finger: Some("mixamorig:{Side}HandMiddle1"),
            finger2: Some("mixamorig:{Side}HandMiddle2"),
            thumb: Some("mixamorig:{Side}HandThumb1"),
            thigh: "mixamorig:{Side}UpLeg",
            knee: "mixamorig:{Side}Leg",
            foot: "mixamorig:{Side}Foot",
            toe: Some("mixamorig:{Side}ToeBase"),
            ..BASE
        },
        Rig {
            name: "HumanIK / MotionBuilder",
            pelvis: "Character1_Hips",
            spine: &["Character1_Spine", "Character1_Spine1", "Character1_Spine2"],
            neck: &["Character1_Neck"],
            head: "Character1_Head",
            clavicle: Some("Character1_{Side}Shoulder"),
            shoulder: "Character1_{Side}Arm",
            twist: Some("Character1_{Side}ArmRoll"),
            elbow: "Character1_{Side}ForeArm",
            wrist: "Character1_{Side}Hand",
            finger: Some("Character1_{Side}HandMiddle1"),
            finger2: Some("Character1_{Side}HandMiddle2"),
            thigh: "Character1_{Side}UpLeg",
            thigh_twist: Some("Character1_{Side}UpLegRoll"),
            knee: "Character1_{Side}Leg",
            foot: "Character1_{Side}Foot",
            toe: Some("Character1_{Side}ToeBase"),
            rest: Rest::Standing,
            ..BASE
        },
        Rig {
            name: "3ds Max Biped",
            root: Some("Bip01"),
            pelvis: "Bip01 Pelvis",
            pre_spine: Some("Bip01 Spine"),
            spine: &["Bip01 Spine1", "Bip01 Spine2"],
            neck: &["Bip01 Neck"],
            neck_hub: true,
            head: "Bip01 Head",
            head_end: End::None,
            head_nub: Some("Bip01 HeadNub"),
            clavicle: Some("Bip01 {S} Clavicle"),
            shoulder: "Bip01 {S} UpperArm",
            elbow: "Bip01 {S} Forearm",
            wrist: "Bip01 {S} Hand",
            finger: Some("Bip01 {S} Finger2"),
            finger2: Some("Bip01 {S} Finger21"),
            thumb: Some("Bip01 {S} Finger0"),
            thigh: "Bip01 {S} Thigh",
            knee: "Bip01 {S} Calf",
            foot: "Bip01 {S} Foot",
            toe: Some("Bip01 {S} Toe0"),
            ..BASE
        },
        Rig {
            name: "Unreal mannequin",
            root: Some("root"),
            pelvis: "pelvis",
            spine: &["spine_01", "spine_02", "spine_03"],
            neck: &["neck_01"],
            head: "head",
            clavicle: Some("clavicle_{s}"),
            shoulder: "upperarm_{s}",
            twist: Some("upperarm_twist_01_{s}"),
            elbow: "lowerarm_{s}",
            wrist: "hand_{s}",
            finger: Some("middle_01_{s}"),
            finger2: Some("middle_02_{s}"),
            thumb: Some("thumb_01_{s}"),
            thigh: "thigh_{s}",
            thigh_twist: Some("thigh_twist_01_{s}"),
            knee: "calf_{s}",
            foot: "foot_{s}",
            toe: Some("ball_{s}"),
            rest: Rest::A,
            ..BASE
        },
        Rig {
            name: "Unity humanoid",
            spine: &["Spine", "Chest", "UpperChest"],
            clavicle: Some("{Side}Shoulder"),
            shoulder: "{Side}UpperArm",
            elbow: "{Side}LowerArm",
            wrist: "{Side}Hand",
            thigh: "{Side}UpperLeg",
            knee: "{Side}LowerLeg",
            foot: "{Side}Foot",
            toe: Some("{Side}Toes"),
            ..BASE
        },
        Rig {
            name: "SMPL",
            pelvis: "pelvis",
            spine: &["spine1", "spine2", "spine3"],
            neck: &["neck"],
            head: "head",
            head_end: End::None,
            clavicle: Some("{side}_collar"),
            shoulder: "{side}_shoulder",
            elbow: "{side}_elbow",
            wrist: "{side}_wrist",
            wrist_end: End::None,
            finger: Some("{side}_hand"),
            finger2: None,
            thigh: "{side}_hip",
            knee: "{side}_knee",
            foot: "{side}_ankle",
            toe: Some("{side}_foot"),
            toe_end: End::None,
            ..BASE
        },
        Rig {
            name: "Bandai",
            root: Some("joint_Root"),
            spine: &["Spine", "Chest"],
            head_end: End::Zero,
            clavicle: Some("Shoulder_{S}"),
            shoulder: "UpperArm_{S}",
            elbow: "LowerArm_{S}",
            wrist: "Hand_{S}",
            wrist_end: End::Zero,
            thigh: "UpperLeg_{S}",
            knee: "LowerLeg_{S}",
            foot: "Foot_{S}",
            toe: Some("Toes_{S}"),
            toe_end: End::Zero,
            rest: Rest::Meaningless,
            ..BASE
        },
        Rig {
            name: "OptiTrack Motive",
            pelvis: "Skeleton_Hip",
            spine: &["Skeleton_Ab", "Skeleton_Chest"],
            neck: &["Skeleton_Neck"],
            head: "Skeleton_Head",
            clavicle: Some("Skeleton_{S}Shoulder"),
            shoulder: "Skeleton_{S}UArm",
            elbow: "Skeleton_{S}FArm",
            wrist: "Skeleton_{S}Hand",
            thigh: "Skeleton_{S}Thigh",
            knee: "Skeleton_{S}Shin",
            foot: "Skeleton_{S}Foot",
            toe: Some("Skeleton_{S}Toe"),
            ..BASE
        },
        Rig {
            name: "Character Creator",
            root: Some("CC_Base_BoneRoot"),
            pelvis: "CC_Base_Hip",
            legs_under: Some("CC_Base_Pelvis"),
            spine: &["CC_Base_Waist", "CC_Base_Spine01", "CC_Base_Spine02"],
            neck: &["CC_Base_NeckTwist01", "CC_Base_NeckTwist02"],
            head: "CC_Base_Head",
            clavicle: Some("CC_Base_{S}_Clavicle"),
            shoulder: "CC_Base_{S}_Upperarm",
            elbow: "CC_Base_{S}_Forearm",
            wrist: "CC_Base_{S}_Hand",
            finger: Some("CC_Base_{S}_Mid1"),
            finger2: Some("CC_Base_{S}_Mid2"),
            thigh: "CC_Base_{S}_Thigh",
            knee: "CC_Base_{S}_Calf",
            foot: "CC_Base_{S}_Foot",
            toe: Some("CC_Base_{S}_ToeBase"),
            rest: Rest::A,
            ..BASE
        },
        Rig {
            name: "Blender Rigify",
            pelvis: "DEF-spine",
            spine: &["DEF-spine.001", "DEF-spine.002", "DEF-spine.003"],
            neck: &["DEF-spine.004", "DEF-spine.005"],
            head: "DEF-spine.006",
            clavicle: Some("DEF-shoulder.{S}"),
            shoulder: "DEF-upper_arm.{S}",
            elbow: "DEF-forearm.{S}",
            wrist: "DEF-hand.{S}",
            thigh: "DEF-thigh.{S}",
            knee: "DEF-shin.{S}",
            foot: "DEF-foot.{S}",
            toe: Some("DEF-toe.{S}"),
            ..BASE
        },
        Rig {
            name: "meaningless names",
            pelvis: "#",
            spine: &["#", "#", "#"],
            neck: &["#"],
            head: "#",
            clavicle: Some("#"),
            shoulder: "#",
            elbow: "#",
            wrist: "#",
            finger: Some("#"),
            finger2: Some("#"),
            thigh: "#",
            knee: "#",
            foot: "#",
            toe: Some("#"),
            ..BASE
        },
        Rig {
            name: "Mixamo mirrored",
            mirrored: true,
            ..rigs_mixamo()
        },
    ]
}

fn rigs_mixamo() -> Rig {
    Rig {
        name: "Mixamo",
        pelvis: "mixamorig:Hips",
        spine: &["mixamorig:Spine", "mixamorig:Spine1", "mixamorig:Spine2"],
        neck: &["mixamorig:Neck"],
        head: "mixamorig:Head",
        clavicle: Some("mixamorig:{Side}Shoulder"),
        shoulder: "mixamorig:{Side}Arm",
        elbow: "mixamorig:{Side}ForeArm",
        wrist: "mixamorig:{Side}Hand",
        finger: Some("mixamorig:{Side}HandMiddle1"),
        finger2: Some("mixamorig:{Side}HandMiddle2"),
        thigh: "mixamorig:{Side}UpLeg",
        knee: "mixamorig:{Side}Leg",
        foot: "mixamorig:{Side}Foot",
        toe: Some("mixamorig:{Side}ToeBase"),
        ..BASE
    }
}

/// One rig joint while building: name, parent, the model link it rides on and its place in
/// that link's frame (model rest coordinates from the link's origin), its End Site's place.
struct RigJoint {
    name: String,
    parent: Option<usize>,
    link: Option<usize>,
    at: DVec3,
    end: Option<DVec3>,
}

struct Builder {
    joints: Vec<RigJoint>,
    counter: usize,
    meaningless: bool,
}

impl Builder {
    fn add(&mut self, name: &str, parent: Option<usize>, link: Option<usize>, at: DVec3) -> usize {
        let name = if self.meaningless {
            self.counter += 1;
            format!("j{:02}", (self.counter * 37) % 101)
        } else {
            name.to_string()
        };
        self.joints.push(RigJoint {
            name,
            parent,
            link,
            at,
            end: None,
        });
        self.joints.len() - 1
    }

    /// Adds a joint at its link's origin (a model joint) and expects `landmark` there.
    fn add_as(
        &mut self,
        expect: &mut BTreeMap<String, String>,
        landmark: String,
        name: &str,
        parent: usize,
        link: Option<usize>,
    ) -> usize {
        let j = self.add(name, Some(parent), link, DVec3::ZERO);
        expect.insert(landmark, self.joints[j].name.clone());
        j
    }
}

fn fill(t: &str, left: bool) -> String {
    let pick = |l: &str, r: &str| if left { l.to_string() } else { r.to_string() };
    t.replace("{Side}", &pick("Left", "Right"))
        .replace("{side}", &pick("left", "right"))
        .replace("{S}", &pick("L", "R"))
        .replace("{s}", &pick("l", "r"))
}

/// A rig's clip carrying `motion`, and where each landmark is expected: (landmark → the rig
/// point at that place, by name `"<joint>"` or `"<joint>:end"`).
fn build(rig: &Rig, motion: &FigureClip) -> (Clip, BTreeMap<String, String>) {
    let model = &motion.model;
    let link = |n: &str| Some(model.joint_index(n).unwrap());
    let mut b = Builder {
        joints: vec![],
        counter: 0,
        meaningless: rig.name == "meaningless names",
    };
    let mut expect: BTreeMap<String, String> = BTreeMap::new();
    let y = |v: f64| DVec3::new(0.0, v, 0.0);
    let root = rig.root.map(|r| b.add(r, None, None, DVec3::ZERO));
    let pelvis = b.add(rig.pelvis, root, link("pelvis"), DVec3::ZERO);
    expect.insert("pelvis".into(), b.joints[pelvis].name.clone());
    let mut base = pelvis;
    if let Some(p) = rig.pre_spine {
        base = b.add(p, Some(pelvis), link("pelvis"), y(0.05));
    }
    let mut spine_parent = base;
    if let Some(l) = rig.lower_back {
        spine_parent = b.add(l, Some(base), link("pelvis"), DVec3::ZERO);
    }
    let legs_parent = match rig.legs_under {
        Some(n) => b.add(n, Some(pelvis), link("pelvis"), DVec3::ZERO),
        None => base,
    };
    // Spine joints on the chest link, from the model waist up towards the neck.
    let neck_h = model.joints[model.joint_index("neck").unwrap()].offset.y;
    let mut prev = spine_parent;
    let ns = rig.spine.len();
    for (i, s) in rig.spine.iter().enumerate() {
        prev = b.add(
            s,
            Some(prev),
            link("waist"),
            y(neck_h * i as f64 / ns as f64),
        );
        if i == 0 {
            expect.insert("waist".into(), b.joints[prev].name.clone());
        }
    }
    let hub = prev;
    let mut neck_parent = hub;
    let mut arm_hub = hub;
    for (i, n) in rig.neck.iter().enumerate() {
        let j = if i == 0 && rig.neck_zero {
            let at = b.joints[hub].at;
            b.add(n, Some(neck_parent), link("waist"), at)
        } else {
            let k = i - usize::from(rig.neck_zero);
            b.add(n, Some(neck_parent), link("neck"), y(0.06 * k as f64))
        };
        if (i == 0 && !rig.neck_zero) || (i == 1 && rig.neck_zero) {
            expect.insert("neck".into(), b.joints[j].name.clone());
        }
        if i == 0 && rig.neck_hub {
            arm_hub = j;
        }
        neck_parent = j;
    }
    let head_top = model.joints[model.joint_index("neck").unwrap()]
        .end_site
        .unwrap();
    let head = b.add(rig.head, Some(neck_parent), link("neck"), y(0.15));
    let head_name = b.joints[head].name.clone();
    match rig.head_end {
        End::Far => {
            b.joints[head].end = Some(head_top);
            expect.insert("head".into(), format!("{head_name}:end"));
        }
        End::Zero => {
            b.joints[head].end = Some(y(0.15));
            expect.insert("head".into(), head_name.clone());
        }
        End::None => {
            expect.insert("head".into(), head_name.clone());
        }
    }
    if let Some(n) = rig.head_nub {
        let j = b.add(n, Some(head), link("neck"), head_top);
        expect.insert("head".into(), b.joints[j].name.clone());
    }
    for left in [true, false] {
        // Names say `named_left`; the geometry says `left`.
        let named_left = left != rig.mirrored;
        let side = if left { "left" } else { "right" };
        let sided = |n: &str| format!("{side}_{n}");
        let f = |t: &str| fill(t, named_left);
        let lk = |n: &str| link(&sided(n));
        if let Some(e) = rig.eyes {
            let x = if left { 0.03 } else { -0.03 };
            let j = b.add(&f(e), Some(head), link("neck"), DVec3::new(x, 0.17, 0.09));
            b.joints[j].end = Some(DVec3::new(x, 0.17, 0.11));
        }
        // Arm.
        let clav_at = model.joints[model.joint_index(&sided("clavicle")).unwrap()].offset;
        let mut arm_parent = arm_hub;
        match rig.clavicle {
            Some(c) => {
                let j = if rig.clavicle_zero {
                    let at = b.joints[arm_hub].at;
                    b.add(&f(c), Some(arm_hub), link("waist"), at)
                } else {
                    b.add(&f(c), Some(arm_hub), lk("clavicle"), DVec3::ZERO)
                };
                let _ = clav_at;
                expect.insert(sided("clavicle"), b.joints[j].name.clone());
                arm_parent = j;
            }
            None => {
                let n = expect["neck"].clone();
                expect.insert(sided("clavicle"), n);
            }
        }
        let sh = b.add_as(
            &mut expect,
            sided("shoulder"),
            &f(rig.shoulder),
            arm_parent,
            lk("shoulder"),
        );
        if let Some(t) = rig.twist {
            b.add(&f(t), Some(sh), lk("shoulder"), y(-0.15));
        }
        let el = b.add_as(&mut expect, sided("elbow"), &f(rig.elbow), sh, lk("elbow"));
        let wr = b.add_as(&mut expect, sided("wrist"), &f(rig.wrist), el, lk("wrist"));
        let wr_name = b.joints[wr].name.clone();
        let hand_end = model.joints[model.joint_index(&sided("wrist")).unwrap()]
            .end_site
            .unwrap();
        match rig.finger {
            Some(fi) => {
                let j = b.add(&f(fi), Some(wr), lk("wrist"), y(-0.09));
                let name = b.joints[j].name.clone();
                match rig.finger2 {
                    Some(f2) => {
                        let k = b.add(&f(f2), Some(j), lk("wrist"), y(-0.14));
                        b.joints[k].end = Some(hand_end);
                        expect.insert(sided("hand"), name);
                    }
                    None if rig.wrist_end == End::None => {
                        expect.insert(sided("hand"), name);
                    }
                    None => {
                        b.joints[j].end = Some(hand_end);
                        expect.insert(sided("hand"), format!("{name}:end"));
                    }
                }
            }
            None => match rig.wrist_end {
                End::Far => {
                    b.joints[wr].end = Some(hand_end);
                    expect.insert(sided("hand"), format!("{wr_name}:end"));
                }
                End::Zero => {
                    b.joints[wr].end = Some(DVec3::ZERO);
                    expect.insert(sided("hand"), format!("{wr_name}:end"));
                }
                End::None => panic!("a rig needs a hand point"),
            },
        }
        if let Some(t) = rig.thumb {
            let x = if left { 0.025 } else { -0.025 };
            let j = b.add(&f(t), Some(wr), lk("wrist"), DVec3::new(x, -0.05, 0.03));
            b.joints[j].end = Some(DVec3::new(x * 1.2, -0.09, 0.05));
        }
        // Leg.
        let hip_at = model.joints[model.joint_index(&sided("hip")).unwrap()].offset;
        let mut leg_parent = legs_parent;
        if let Some(hh) = rig.hip_helper {
            leg_parent = b.add(&f(hh), Some(leg_parent), link("pelvis"), DVec3::ZERO);
        }
        if let Some(bt) = rig.buttock {
            leg_parent = b.add(&f(bt), Some(leg_parent), link("pelvis"), hip_at + y(0.05));
        }
        let th = b.add_as(
            &mut expect,
            sided("hip"),
            &f(rig.thigh),
            leg_parent,
            lk("hip"),
        );
        if let Some(t) = rig.thigh_twist {
            b.add(&f(t), Some(th), lk("hip"), y(-0.2));
        }
        let kn = b.add_as(&mut expect, sided("knee"), &f(rig.knee), th, lk("knee"));
        let ft = b.add_as(&mut expect, sided("ankle"), &f(rig.foot), kn, lk("ankle"));
        let ft_name = b.joints[ft].name.clone();
        let toe_tip = model.joints[model.joint_index(&sided("ankle")).unwrap()]
            .end_site
            .unwrap();
        match rig.toe {
            Some(t) => {
                let j = b.add(&f(t), Some(ft), lk("ankle"), toe_tip * 0.65);
                expect.insert(sided("toe"), b.joints[j].name.clone());
                b.joints[j].end = match rig.toe_end {
                    End::Far => Some(toe_tip),
                    End::Zero => Some(toe_tip * 0.65),
                    End::None => None,
                };
            }
            None => {
                b.joints[ft].end = Some(toe_tip);
                expect.insert(sided("toe"), format!("{ft_name}:end"));
                assert!(rig.foot_end != End::None);
            }
        }
    }
    (clip_of(&b.joints, rig.rest, motion), expect)
}

/// The rest orientation of each model link in a rig's rest pose.
fn rest_rotations(model: &Figure, rest: Rest) -> Vec<DQuat> {
    model
        .joints
        .iter()
        .enumerate()
        .map(|(i, j)| {
            let arm = ["shoulder", "elbow", "wrist"]
                .iter()
                .any(|p| j.name.ends_with(p));
            let sign = if j.name.starts_with("left_") {
                1.0
            } else {
                -1.0
            };
            match rest {
                Rest::Standing => DQuat::IDENTITY,
                Rest::T if arm => DQuat::from_rotation_z(sign * 90f64.to_radians()),
                Rest::A if arm => DQuat::from_rotation_z(sign * 45f64.to_radians()),
                Rest::T | Rest::A => DQuat::IDENTITY,
                Rest::Meaningless => {
                    let k = i as f64 + 1.0;
                    DQuat::from_axis_angle(
                        DVec3::new(k.sin(), (2.0 * k).cos(), 0.5).normalize(),
                        1.0 + 0.7 * k,
                    )
                }
            }
        })
        .collect()
}

/// The rig's clip: each rig joint rides its model link, its frame turned by the inverse of the
/// link's rest orientation so that the rig's rest pose is `rest` and its motion is the model's.
fn clip_of(joints: &[RigJoint], rest: Rest, motion: &FigureClip) -> Clip {
    let model = &motion.model;
    let mclip = motion.to_clip();
    let p = rest_rotations(model, rest);
    // Model link origins in the rig's rest pose.
    let mut origin = vec![DVec3::ZERO; model.joints.len()];
    for (i, j) in model.joints.iter().enumerate() {
        origin[i] = match j.parent {
            Some(q) => origin[q] + p[q] * j.offset,
            None => j.offset,
        };
    }
    let world =
        |link: Option<usize>, at: DVec3| -> DVec3 { link.map_or(at, |l| origin[l] + p[l] * at) };
    let rest_pos: Vec<DVec3> = joints.iter().map(|j| world(j.link, j.at)).collect();
    let skeleton = Skeleton {
        joints: joints
            .iter()
            .enumerate()
            .map(|(k, j)| Joint {
                name: j.name.clone(),
                parent: j.parent,
                offset: match j.parent {
                    Some(q) => rest_pos[k] - rest_pos[q],
                    None => rest_pos[k],
                },
                end_site: j.end.map(|e| world(j.link, e) - rest_pos[k]),
            })
            .collect(),
    };
    let n = joints.len();
    let frames = motion.frame_count();
    let mut translations = Vec::with_capacity(frames * n);
    let mut rotations = Vec::with_capacity(frames * n);
    let mut g = vec![];
    let mut rig_g = vec![Transform::IDENTITY; n];
    for f in 0..frames {
        mclip.globals(f, &mut g);
        for (k, j) in joints.iter().enumerate() {
            let (pos, rot) = match j.link {
                Some(l) => (
                    g[l].translation + g[l].rotation * j.at,
                    g[l].rotation * p[l].inverse(),
                ),
                None => (j.at, DQuat::IDENTITY),
            };
            rig_g[k] = Transform {
                rotation: rot,
                translation: pos,
            };
            match j.parent {
                Some(q) => {
                    let pg = rig_g[q];
                    let t = pg.rotation.inverse() * (pos - pg.translation);
                    // Rigid on the rig's skeleton except where the root moves the pelvis.
                    if joints[q].link.is_some() {
                        let off = skeleton.joints[k].offset;
                        assert!(
                            (t - off).length() < 1e-9,
                            "joint {} moves against its parent: {t} vs {off}",
                            j.name
                        );
                    }
                    translations.push(t);
                    rotations.push(pg.rotation.inverse() * rot);
                }
                None => {
                    translations.push(pos);
                    rotations.push(rot);
                }
            }
        }
    }
    Clip {
        skeleton,
        frame_time: motion.frame_time,
        translations,
        rotations,
    }
}

/// First-frame position of a point named `"<joint>"` or `"<joint>:end"`.
fn point(clip: &Clip, name: &str) -> DVec3 {
    let (j, end) = match name.strip_suffix(":end") {
        Some(j) => (j, true),
        None => (name, false),
    };
    let i = clip
        .skeleton
        .index(j)
        .unwrap_or_else(|| panic!("no joint {j}"));
    let mut g = vec![];
    clip.globals(0, &mut g);
    let e = if end {
        clip.skeleton.joints[i].end_site.unwrap()
    } else {
        DVec3::ZERO
    };
    g[i].translation + g[i].rotation * e
}

fn check_rig(rig: &Rig, motion: &FigureClip) -> AutoMapping {
    let (clip, expect) = build(rig, motion);
    // The rig really carries the motion: its rest pose is not the motion's first frame.
    let auto = Mapping::automatic(&clip, Synonyms::builtin())
        .unwrap_or_else(|e| panic!("{}: {e}", rig.name));
    for (l, want) in &expect {
        let got = &auto.mapping.landmarks[l];
        let d = (point(&clip, got) - point(&clip, want)).length();
        let finding = auto.findings.iter().find(|f| &f.landmark == l).unwrap();
        assert!(
            d < 1e-6,
            "{}: {l} found at '{got}' ({:.2}: {}), expected '{want}' ({d:.3} m away)",
            rig.name,
            finding.confidence,
            finding.reason
        );
        assert!(finding.confidence > 0.0 && finding.confidence <= 1.0);
        assert!(!finding.reason.is_empty());
    }
    // Through the same retargeting and report as `export --bvh --model`.
    let model = Figure::by_name("humanoid24").unwrap();
    let mapped = retarget(&clip, &auto.mapping, &model).unwrap();
    let errs = effector_errors(&clip, &auto.mapping, &mapped).unwrap();
    for e in &errs {
        println!(
            "{:<24} {:<11} mean {:5.1} mm, worst {:5.1} mm",
            rig.name,
            e.effector,
            e.mean_m * 1e3,
            e.max_m * 1e3
        );
        let limit = match e.effector.as_str() {
            "left_foot" | "right_foot" => 0.05,
            "head" => 0.25,
            _ => 0.15,
        };
        assert!(
            e.max_m < limit,
            "{} {}: worst {:.3} m",
            rig.name,
            e.effector,
            e.max_m
        );
    }
    auto
}

#[test]
fn every_convention_maps_automatically_with_every_landmark_and_side_right() {
    let motion = motion();
    for rig in rigs()
        .iter()
        .filter(|r| !r.mirrored && r.name != "meaningless names")
    {
        let auto = check_rig(rig, &motion);
        // The names carry the sides here, and geometry agrees.
        for n in &auto.notes[auto.notes.len() - 2..] {
            assert!(n.contains("geometry and names agree"), "{}: {n}", rig.name);
        }
    }
}

#[test]
fn meaningless_names_map_by_structure_alone() {
    let motion = motion();
    let rig = rigs()
        .into_iter()
        .find(|r| r.name == "meaningless names")
        .unwrap();
    let auto = check_rig(&rig, &motion);
    assert!(
        auto.findings
            .iter()
            .all(|f| f.reason.starts_with("structure") || f.landmark.ends_with("clavicle")),
        "{:?}",
        auto.findings
    );
    assert!(auto.notes.iter().any(|n| n.contains("legs: by geometry")));
}

#[test]
fn a_mirrored_rig_is_mapped_by_its_geometry_not_its_side_words() {
    // Names say "Left" on the figure's right. Geometry wins: the model must move the way the
    // figure moves; a figure mapped by the names would have its knee kick on the wrong leg and
    // its pelvis turned round.
    let motion = motion();
    let rig = rigs().into_iter().find(|r| r.mirrored).unwrap();
    let auto = check_rig(&rig, &motion);
    assert!(auto.mapping.landmarks["left_hip"].contains("Right"));
    assert!(
        auto.notes.iter().any(|n| n.contains("geometry wins")),
        "{:?}",
        auto.notes
    );
    let f = auto
        .findings
        .iter()
        .find(|f| f.landmark == "left_knee")
        .unwrap();
    assert!(
        f.confidence < 1.0 && f.reason.contains("against the names"),
        "{f:?}"
    );
    // Had the names won, the feet would be far off: the check above can fail.
    let mut by_names = auto.mapping.clone();
    for (k, v) in &auto.mapping.landmarks {
        if let Some(rest) = k.strip_prefix("left_") {
            let r = format!("right_{rest}");
            by_names
                .landmarks
                .insert(k.clone(), auto.mapping.landmarks[&r].clone());
            by_names.landmarks.insert(r, v.clone());
        }
    }
    let (clip, _) = build(&rig, &motion);
    let model = Figure::by_name("humanoid24").unwrap();
    let mapped = retarget(&clip, &by_names, &model).unwrap();
    let errs = effector_errors(&clip, &auto.mapping, &mapped).unwrap();
    let foot = errs.iter().find(|e| e.effector == "right_foot").unwrap();
    assert!(
        foot.max_m > 0.1,
        "mapped by the names, the right foot is off by only {}",
        foot.max_m
    );
}

#[test]
fn the_mapping_file_written_reads_back_as_the_same_mapping() {
    let motion = motion();
    let (clip, _) = build(&rigs_mixamo(), &motion);
    let auto = Mapping::automatic(&clip, Synonyms::builtin()).unwrap();
    let text = auto.to_ron("a Mixamo rig");
    let back = Mapping::parse(&text, "written.ron").unwrap();
    assert_eq!(back, auto.mapping);
    // And detect() falls back to it when no built-in file fits.
    assert!(Mapping::builtin_for(&clip.skeleton).is_none());
    assert_eq!(Mapping::detect_clip(&clip).unwrap(), auto.mapping);
    // Without a clip, detect() looks at the rest pose (a T pose here) and finds the same.
    assert_eq!(
        Mapping::detect(&clip.skeleton).unwrap().landmarks,
        auto.mapping.landmarks
    );
}

/// A one-frame clip of a skeleton at rest.
fn at_rest(joints: &[(&str, Option<usize>, [f64; 3])], ends: &[usize]) -> Clip {
    let skeleton = Skeleton {
        joints: joints
            .iter()
            .enumerate()
            .map(|(i, (n, p, o))| Joint {
                name: n.to_string(),
                parent: *p,
                offset: DVec3::from_array(*o),
                end_site: ends.contains(&i).then_some(DVec3::new(0.0, -0.05, 0.05)),
            })
            .collect(),
    };
    let n = skeleton.joints.len();
    Clip {
        translations: skeleton.joints.iter().map(|j| j.offset).collect(),
        rotations: vec![DQuat::IDENTITY; n],
        skeleton,
        frame_time: 1.0 / 30.0,
    }
}

fn refusal(clip: &Clip) -> String {
    let e = Mapping::detect_clip(clip).unwrap_err().to_string();
    assert!(e.contains("no mapping for this skeleton"), "{e}");
    e
}

#[test]
fn non_humanoids_are_refused_naming_what_is_missing() {
    // A quadruped: four legs to the floor, a horizontal spine, a neck and head forward, a tail.
    let mut q: Vec<(&str, Option<usize>, [f64; 3])> = vec![
        ("Hips", None, [0.0, 0.6, 0.0]),
        ("Spine", Some(0), [0.0, 0.0, 0.3]),
        ("Chest", Some(1), [0.0, 0.0, 0.3]),
        ("Neck", Some(2), [0.0, 0.15, 0.15]),
        ("Head", Some(3), [0.0, 0.1, 0.15]),
        ("Tail", Some(0), [0.0, 0.0, -0.3]),
        ("Tail1", Some(5), [0.0, -0.1, -0.3]),
    ];
    for (root, names) in [
        (0, ["LeftUpLeg", "LeftLeg", "LeftFoot"]),
        (0, ["RightUpLeg", "RightLeg", "RightFoot"]),
        (2, ["LeftArm", "LeftForeArm", "LeftHand"]),
        (2, ["RightArm", "RightForeArm", "RightHand"]),
    ] {
        let x = if names[0].starts_with("Left") {
            0.1
        } else {
            -0.1
        };
        let a = q.len();
        q.push((names[0], Some(root), [x, -0.05, 0.0]));
        q.push((names[1], Some(a), [0.0, -0.25, 0.0]));
        q.push((names[2], Some(a + 1), [0.0, -0.25, 0.0]));
    }
    let ends: Vec<usize> = vec![4, 6, 9, 12, 15, 18];
    let e = refusal(&at_rest(&q, &ends));
    assert!(e.contains("4 limbs reach the floor"), "{e}");

    // A single chain.
    let chain: Vec<(&str, Option<usize>, [f64; 3])> = (0..6)
        .map(|i| {
            (
                ["a", "b", "c", "d", "e", "f"][i],
                i.checked_sub(1),
                [0.0, if i == 0 { 1.0 } else { -0.15 }, 0.0],
            )
        })
        .collect();
    let e = refusal(&at_rest(&chain, &[5]));
    assert!(e.contains("found 1 limb end(s)"), "{e}");

    // A humanoid with a third leg from the pelvis.
    let motion = motion();
    let (clip, _) = build(&rigs_mixamo(), &motion);
    let mut sk = clip.skeleton.clone();
    let hips = sk.index("mixamorig:Hips").unwrap();
    let n0 = sk.joints.len();
    for (k, (name, off)) in [
        ("ThirdUpLeg", [0.0, -0.05, 0.1]),
        ("ThirdLeg", [0.0, -0.41, 0.0]),
        ("ThirdFoot", [0.0, -0.41, 0.0]),
    ]
    .iter()
    .enumerate()
    {
        sk.joints.push(Joint {
            name: name.to_string(),
            parent: Some(if k == 0 { hips } else { n0 + k - 1 }),
            offset: DVec3::from_array(*off),
            end_site: (k == 2).then_some(DVec3::new(0.0, -0.06, 0.15)),
        });
    }
    // First frame only: the rig's first frame, the new leg at rest under the hips.
    let n = sk.joints.len();
    let mut translations = clip.frame_translations(0).to_vec();
    let mut rotations = clip.frame_rotations(0).to_vec();
    for j in n0..n {
        translations.push(sk.joints[j].offset);
        rotations.push(if j == n0 {
            clip.frame_rotations(0)[hips].inverse()
        } else {
            DQuat::IDENTITY
        });
    }
    let three = Clip {
        skeleton: sk,
        frame_time: clip.frame_time,
        translations,
        rotations,
    };
    let e = refusal(&three);
    assert!(e.contains("3 limbs reach the floor"), "{e}");
    assert!(e.contains("ThirdFoot"), "{e}");
}
