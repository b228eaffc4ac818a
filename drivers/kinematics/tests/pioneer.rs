//! Pioneer closed-form kinematics: reference FK vectors, FK→IK→FK round trips, reach,
//! orientation consistency, limits, NaN handling, SETPOSITION and VECMOVE.

use std::f64::consts::{FRAC_PI_2, PI};

use limber_kinematics::Pose;
use limber_kinematics::pioneer::*;
use nalgebra::{Rotation3, Vector3};
use proptest::prelude::*;

struct FkCase {
    theta: [f64; 5],
    p: [f64; 3],
    a: [f64; 3],
    o: [f64; 3],
    n: [f64; 3],
}

/// The 40 vectors of shared/spec/pioneer-fk-vectors.json (12 decimals).
/// They are reference data, so their rounded π/2 etc. stay as given.
#[allow(clippy::approx_constant)]
const FK_CASES: &[FkCase] = &[
    FkCase {
        theta: [0.0, 0.0, 0.0, 0.0, 0.0],
        p: [0.47971, 0.0, 0.0],
        a: [1.0, 0.0, 0.0],
        o: [0.0, 0.0, 1.0],
        n: [0.0, 1.0, 0.0],
    },
    FkCase {
        theta: [1.570796326795, 0.0, 0.0, 0.0, 0.0],
        p: [0.0, 0.47971, 0.0],
        a: [0.0, 1.0, 0.0],
        o: [0.0, 0.0, 1.0],
        n: [-1.0, 0.0, 0.0],
    },
    FkCase {
        theta: [0.0, 0.785398163397, 0.0, 0.0, 0.0],
        p: [0.359342602796, 0.0, 0.290592602796],
        a: [0.707106781187, 0.0, 0.707106781187],
        o: [-0.707106781187, 0.0, 0.707106781187],
        n: [0.0, 1.0, 0.0],
    },
    FkCase {
        theta: [0.0, 0.0, -1.570796326795, 0.0, 0.0],
        p: [0.22875, 0.0, -0.25096],
        a: [0.0, 0.0, -1.0],
        o: [1.0, 0.0, 0.0],
        n: [0.0, 1.0, 0.0],
    },
    FkCase {
        theta: [0.0, 0.0, 0.0, 1.570796326795, 0.0],
        p: [0.47971, 0.0, 0.0],
        a: [1.0, 0.0, 0.0],
        o: [0.0, -1.0, 0.0],
        n: [0.0, 0.0, 1.0],
    },
    FkCase {
        theta: [0.0, 0.0, 0.0, 0.0, 0.785398163397],
        p: [0.446551558698, 0.0, 0.080051558698],
        a: [0.707106781187, 0.0, 0.707106781187],
        o: [-0.707106781187, 0.0, 0.707106781187],
        n: [0.0, 1.0, 0.0],
    },
    FkCase {
        theta: [0.3, -0.4, 0.9, -0.7, 0.5],
        p: [0.375903316411, 0.152880618881, 0.087795952215],
        a: [0.476534444162, 0.470703227837, 0.742531746682],
        o: [-0.876441264438, 0.320670369315, 0.359195245284],
        n: [0.069033568058, 0.821954369504, -0.565354208381],
    },
    FkCase {
        theta: [
            1.426218857684,
            0.014775914802,
            0.379351803317,
            0.504816002036,
            -1.391373036897,
        ],
        p: [0.006048324841, 0.41547903295, -0.027004163293],
        a: [-0.399530281963, 0.558880915157, -0.726655128977],
        o: [0.207663107599, 0.827239400941, 0.522064179267],
        n: [-0.892889459864, -0.057680986509, 0.446566138728],
    },
    FkCase {
        theta: [
            0.384021752776,
            0.912531361375,
            -0.98617709942,
            -0.006290322889,
            -0.023300344642,
        ],
        p: [0.386341445213, 0.156096345432, 0.105475208584],
        a: [0.922866726075, 0.372757239065, -0.096793835697],
        o: [0.087386941423, 0.042094210084, 0.995284682865],
        n: [-0.375074030523, 0.926973634038, -0.006273230832],
    },
    FkCase {
        theta: [
            0.39435138618,
            -0.602469755741,
            0.084943017248,
            1.321101993886,
            0.612137425077,
        ],
        p: [0.401608497393, 0.098854123894, -0.19068682759],
        a: [0.935438197857, -0.213804178377, -0.28150160088],
        o: [-0.063972552838, -0.885592446512, 0.460036445475],
        n: [0.347653405668, 0.412327287467, 0.842094601299],
    },
    FkCase {
        theta: [
            0.052333283534,
            1.220536379877,
            -0.49022400817,
            1.099146117755,
            -0.326461834687,
        ],
        p: [0.315033299438, 0.048888002571, 0.301423709138],
        a: [0.786779356073, 0.327284349769, 0.523319404622],
        o: [-0.003984612245, -0.845134721183, 0.534538516775],
        n: [-0.617221490004, 0.422649094932, 0.6636304505],
    },
    FkCase {
        theta: [
            0.056225782761,
            -0.392931939552,
            0.57635289349,
            -0.190660277043,
            -0.826554117221,
        ],
        p: [0.442501422684, 0.009099582972, -0.102547908337],
        a: [0.804362609365, -0.094348810168, -0.586599603371],
        o: [0.593779124971, 0.161999079762, 0.788151412424],
        n: [-0.02066744794, 0.98227012587, -0.186328356456],
    },
    FkCase {
        theta: [
            0.400572103734,
            -0.665309505551,
            -0.84236168974,
            -0.011700268342,
            -0.863885102392,
        ],
        p: [0.112780941051, 0.046665353418, -0.31505611801],
        a: [-0.657539240757, -0.288107807863, -0.696158055267],
        o: [0.638047799274, 0.278444946995, -0.717888164921],
        n: [-0.400670878286, 0.916221754021, -0.000738073721],
    },
    FkCase {
        theta: [
            0.320467928135,
            -0.712519913853,
            -1.319382769582,
            -0.150722784771,
            -0.466859837073,
        ],
        p: [0.038891275002, 0.004847048236, -0.296084577428],
        a: [-0.734026429136, -0.314836512122, -0.601733472532],
        o: [0.518100278855, 0.313239038441, -0.795897861441],
        n: [-0.439064121035, 0.895968345106, 0.066808848128],
    },
    FkCase {
        theta: [
            -0.938482891415,
            0.16021559307,
            0.780096367139,
            1.246531458059,
            -0.705846588663,
        ],
        p: [0.279319808954, -0.263458145374, 0.192592520885],
        a: [0.859831019049, -0.133196378096, 0.49289891818],
        o: [-0.471669954752, -0.576843330611, 0.666917705353],
        n: [-0.195494430777, 0.805922140651, 0.558812518421],
    },
    FkCase {
        theta: [
            0.114221816518,
            -1.115944622522,
            -0.226889178537,
            0.223559416656,
            -0.845934425655,
        ],
        p: [0.103799382327, 0.030820006484, -0.369714220334],
        a: [-0.576494610307, 0.100916436656, -0.810845137556],
        o: [0.81052942047, -0.054974705435, -0.583112202165],
        n: [0.103421578204, 0.993374881188, 0.050103119532],
    },
    FkCase {
        theta: [
            -1.251510868096,
            1.061244949837,
            -0.533232150832,
            -1.098489700934,
            -0.124823646313,
        ],
        p: [0.102980698726, -0.35148693318, 0.260129540555],
        a: [0.172721086791, -0.875666631418, 0.450971592008],
        o: [0.801306892238, 0.391170795296, 0.452650718943],
        n: [0.572778046567, -0.283184320767, -0.769241151943],
    },
    FkCase {
        theta: [
            0.187546197767,
            -0.411782613823,
            0.886440728434,
            -0.395041009469,
            1.251918331143,
        ],
        p: [0.310719290479, 0.10107766897, 0.103392187082],
        a: [-0.187727194266, 0.336341450877, 0.922839600881],
        o: [-0.982220947243, -0.063599296089, -0.176627122307],
        n: [0.000715073562, 0.939590101033, -0.34230093589],
    },
    FkCase {
        theta: [
            -0.300580988549,
            -0.199092916815,
            -1.014362808935,
            -0.663690170175,
            -1.214192071231,
        ],
        p: [0.18057331274, -0.12439348313, -0.226948349731],
        a: [-0.714814842284, -0.38279597339, -0.585240962345],
        o: [0.622822250788, 0.032088188478, -0.781705054406],
        n: [-0.318012869511, 0.923275468599, -0.215476736353],
    },
    FkCase {
        theta: [
            0.80203960769,
            -1.135314716844,
            -0.950666517814,
            -0.034820797011,
            -0.649559157886,
        ],
        p: [-0.023031469219, -0.027239826781, -0.309673771227],
        a: [-0.623353320785, -0.674740110683, -0.39516632005],
        o: [0.254391328447, 0.302878992244, -0.91844943686],
        n: [-0.739402251469, 0.673045391555, 0.017152592498],
    },
    FkCase {
        theta: [
            1.048599262646,
            -0.099867633697,
            -0.786482089636,
            -0.987162938428,
            -0.292524706808,
        ],
        p: [0.207983721893, 0.306790012415, -0.218036383578],
        a: [0.449113108235, 0.297968308632, -0.842325532714],
        o: [-0.397682380002, 0.910883319199, 0.110183045159],
        n: [-0.800091332691, -0.2854933727, -0.527586384867],
    },
    FkCase {
        theta: [
            -0.950976424021,
            -1.087890776328,
            -0.063334222801,
            0.486778899746,
            -1.2621859584,
        ],
        p: [0.114323280385, -0.073338648876, -0.337744951045],
        a: [-0.012079560263, 0.784168170256, -0.62043078984],
        o: [0.252220755638, -0.598023433789, -0.760757953008],
        n: [0.967594323386, 0.165675144174, 0.190559628342],
    },
    FkCase {
        theta: [
            0.47832547765,
            -0.213345364518,
            -0.65755533999,
            -0.83098379622,
            -1.241502349411,
        ],
        p: [0.286941080498, 0.059647788999, -0.21376548283],
        a: [0.073431898201, -0.749195165255, -0.658266177686],
        o: [0.579219177774, 0.569354192168, -0.583387476691],
        n: [-0.811857684835, 0.338441144396, -0.475756966691],
    },
    FkCase {
        theta: [
            -0.332937212806,
            -0.853662443833,
            0.264154258265,
            -0.849093118147,
            0.596771142673,
        ],
        p: [0.38382449779, -0.082196111825, -0.214296025828],
        a: [0.982738123428, 0.106535420815, -0.151248090478],
        o: [0.048591006516, 0.640204986809, 0.766665826127],
        n: [-0.17850684818, 0.760781032214, -0.623977184019],
    },
    FkCase {
        theta: [
            -0.455541290653,
            0.330423183127,
            0.787239391324,
            0.422584971529,
            0.549263965929,
        ],
        p: [0.235581181289, -0.142404598373, 0.286170366323],
        a: [-0.143310920375, -0.168210997988, 0.97527792975],
        o: [-0.987190613012, 0.094116153049, -0.128828736376],
        n: [0.070118996586, 0.981247782108, 0.179544190734],
    },
    FkCase {
        theta: [
            1.144896043714,
            -0.277578213913,
            0.62715846253,
            -1.334316770065,
            -0.051627162585,
        ],
        p: [0.194693743569, 0.415407225261, 0.040772713235],
        a: [0.43503258232, 0.837491376037, 0.330688444588],
        o: [-0.897219449902, 0.372282715609, 0.237492817526],
        n: [-0.075788594377, 0.400017218033, -0.91336866283],
    },
    FkCase {
        theta: [
            -0.559468502363,
            1.423985697159,
            -1.29322643195,
            0.354273194627,
            0.44678566814,
        ],
        p: [0.265573640354, -0.186326096785, 0.235037032984],
        a: [0.633485416657, -0.573546324851, 0.519365805702],
        o: [-0.622583938857, 0.020732032912, 0.782278353202],
        n: [0.459440383467, 0.818910737542, 0.343947289536],
    },
    FkCase {
        theta: [
            0.635357542538,
            -1.448638994916,
            -0.765839018001,
            1.431217660976,
            -0.140229709037,
        ],
        p: [-0.060375429715, -0.025049320392, -0.357338407117],
        a: [-0.572951954179, -0.250498180293, -0.780369604657],
        o: [0.603101275786, -0.77359383008, -0.194477343688],
        n: [0.554972890643, 0.582068078263, -0.594307868801],
    },
    FkCase {
        theta: [
            -0.874621073832,
            0.136610234166,
            -0.790146391967,
            0.945221708854,
            1.450555389321,
        ],
        p: [0.178540087669, -0.3556942909, -0.017966926742],
        a: [-0.329767551616, -0.860367468094, 0.388614438417],
        o: [-0.55268977816, 0.509667304923, 0.659373374811],
        n: [0.765367474497, -0.002656715653, 0.64358804436],
    },
    FkCase {
        theta: [
            0.269993721011,
            -1.386843873909,
            0.200587559995,
            0.197633209952,
            1.271457834568,
        ],
        p: [0.256765255874, 0.049021516825, -0.276146747485],
        a: [0.993701630458, 0.080338025555, 0.078120876045],
        o: [-0.071700201864, -0.07992063065, 0.994219177973],
        n: [-0.086117075408, 0.993558500767, 0.073657008335],
    },
    FkCase {
        theta: [
            0.957906244678,
            0.477154724933,
            -1.41946757517,
            -0.604948459901,
            1.445782005092,
        ],
        p: [0.163401056977, 0.343412558506, 0.004952117718],
        a: [-0.039655323385, 0.924569462455, 0.378944276146],
        o: [-0.345834280476, -0.368503251903, 0.862904400142],
        n: [-0.937457255439, 0.096833168043, -0.334360930421],
    },
    FkCase {
        theta: [
            -1.343108006953,
            -0.255951380092,
            -1.321039858463,
            0.839533564023,
            -0.611457779843,
        ],
        p: [0.087464844748, -0.16317864803, -0.270680972326],
        a: [0.328585636905, 0.474855272721, -0.816421428668],
        o: [-0.471113487387, -0.66679629039, -0.577438125797],
        n: [0.818586318736, -0.574365020776, -0.004611039772],
    },
    FkCase {
        theta: [
            -0.529924685906,
            -0.682426293084,
            -0.049696618557,
            -0.87210369844,
            0.762574552256,
        ],
        p: [0.36666997813, -0.145403484176, -0.210292684508],
        a: [0.987648355775, 0.034418792015, -0.152859648342],
        o: [0.104781960114, 0.580256262161, 0.807665407863],
        n: [-0.116496635873, 0.813706345668, -0.569482674759],
    },
    FkCase {
        theta: [
            -0.914353306922,
            -0.131733687822,
            -0.44960101988,
            0.401947304725,
            0.761944110598,
        ],
        p: [0.250681309559, -0.375478639909, -0.081530166935],
        a: [0.368000512473, -0.920170492029, 0.133648376039],
        o: [-0.353167906035, -0.005359825899, 0.935544602044],
        n: [0.860144204751, 0.391481210104, 0.326947104543],
    },
    FkCase {
        theta: [
            -0.34006044145,
            0.138159425365,
            0.85067207445,
            0.7806360005,
            -0.623694336414,
        ],
        p: [0.385728068066, -0.087116085227, 0.188056800054],
        a: [0.884500109627, 0.123031532672, 0.450025330442],
        o: [-0.342071268821, -0.484910121109, 0.804890937639],
        n: [-0.317248803178, 0.865866858365, 0.386817502794],
    },
    FkCase {
        theta: [
            1.293066746409,
            -0.06140756709,
            -1.015104508885,
            -0.068615067035,
            -0.815865006871,
        ],
        p: [0.076224107043, 0.2467426358, -0.238396001522],
        a: [-0.038222333201, -0.316194937217, -0.947923949968],
        o: [0.214548310087, 0.923897586391, -0.316831615373],
        n: [-0.975965202189, 0.215485525127, -0.032525568048],
    },
    FkCase {
        theta: [
            0.187013124523,
            1.349296415879,
            0.987449733136,
            1.38299799484,
            1.318674532155,
        ],
        p: [-0.005442779236, -0.110644482955, 0.261536331427],
        a: [-0.121064731947, -0.991149502999, 0.05446093447],
        o: [0.672185033564, -0.122228379654, -0.730224283258],
        n: [-0.730418107204, 0.051796582049, -0.681033407959],
    },
    FkCase {
        theta: [
            -0.334195183036,
            -1.49040603085,
            -0.036574236942,
            1.14709032042,
            -1.174896149891,
        ],
        p: [0.07529227975, 0.074650045139, -0.34259841993],
        a: [-0.06617574058, 0.913295967086, -0.401884620087],
        o: [0.07250704953, -0.397301240976, -0.914819354675],
        n: [0.995170085527, 0.089678316346, 0.039928692066],
    },
    FkCase {
        theta: [
            0.743823123252,
            0.602143242263,
            -1.199335963697,
            0.515693663489,
            -0.540606878726,
        ],
        p: [0.250085656173, 0.269154586143, -0.083330815069],
        a: [0.164621026188, 0.496358314177, -0.852366318953],
        o: [0.908122162414, 0.261018969639, 0.327388508689],
        n: [-0.384985786581, 0.827947776998, 0.407784774966],
    },
    FkCase {
        theta: [
            0.870492994421,
            0.886189228596,
            -0.147669972037,
            -0.59679703428,
            0.653463057755,
        ],
        p: [0.163717218145, 0.25427142132, 0.319286664212],
        a: [-0.101033924903, 0.410279415989, 0.906345931107],
        o: [-0.915827706515, -0.394242153322, 0.076372354444],
        n: [-0.388653776513, 0.822340516671, -0.415577088688],
    },
];

fn v(a: [f64; 3]) -> Vector3<f64> {
    Vector3::from(a)
}

fn geom() -> PioneerGeometry {
    PioneerGeometry::default()
}

fn opts() -> PioneerIkOptions {
    PioneerIkOptions::default()
}

#[test]
fn fk_matches_the_40_reference_vectors() {
    assert_eq!(FK_CASES.len(), 40);
    let g = geom();
    for (i, c) in FK_CASES.iter().enumerate() {
        let pose = g.fk(&c.theta).unwrap();
        for (name, got, want) in [
            ("p", pose.position, v(c.p)),
            ("a", pose.approach(), v(c.a)),
            ("o", pose.orientation(), v(c.o)),
            ("n", pose.normal(), v(c.n)),
        ] {
            assert!(
                (got - want).norm() < 2e-12,
                "case {i} {name}: got {got:?} want {want:?}"
            );
        }
    }
}

#[test]
fn fk_at_zero_is_stretched_forward_and_robot_frame_adds_the_base() {
    let g = geom();
    let p = g.fk(&[0.0; 5]).unwrap();
    assert!((p.position - Vector3::new(0.47971, 0.0, 0.0)).norm() < 1e-15);
    let r = g.fk_robot(&[0.0; 5]).unwrap();
    assert!((r.position - Vector3::new(0.58471, 0.0, 0.3185)).norm() < 1e-15);
    assert_eq!(g.robot_to_base(&r).position, p.position);
}

/// Player's a_y carries +c1·s4·s5; with it the frame is not orthonormal, with the
/// corrected sign it is.
#[test]
fn player_sign_error_is_corrected() {
    let t = [0.3, -0.4, 0.9, -0.7, 0.5];
    let pose = geom().fk(&t).unwrap();
    let (s1, c1) = t[0].sin_cos();
    let (s23, c23) = (t[1] + t[2]).sin_cos();
    let (s4, c4) = t[3].sin_cos();
    let (s5, c5) = t[4].sin_cos();
    let player_ay = s1 * c23 * c5 + c1 * s4 * s5 - s1 * s23 * c4 * s5;
    let mut a_player = pose.approach();
    a_player.y = player_ay;
    assert!(
        (a_player.norm() - 1.0).abs() > 1e-3,
        "Player's a is not unit"
    );
    assert!((pose.approach().norm() - 1.0).abs() < 1e-15);
    assert!((pose.normal() - pose.orientation().cross(&pose.approach())).norm() < 1e-15);
}

#[test]
fn driver_angle_map_round_trips_and_swaps_reversed_limits() {
    let map = DriverAngleMap {
        offsets: [0.1, -0.2, 0.3, 0.05, -0.4],
    };
    let j = [0.5, -0.25, 1.0, 0.3, -0.7];
    let t = map.theta_from_driver(&j);
    assert!((t[0] - -(0.5 - 0.1)).abs() < 1e-15);
    assert!((t[1] - (-0.25 + 0.2)).abs() < 1e-15);
    assert!((t[3] - -(0.3 - 0.05)).abs() < 1e-15);
    let back = map.driver_from_theta(&t);
    for i in 0..5 {
        assert!((back[i] - j[i]).abs() < 1e-15);
    }
    // ARMINFO limits of joints 0-2 come out reversed (min > max) in driver radians.
    let lim = DriverAngleMap::default()
        .limits_from_driver(&[1.5, 1.4, 1.3, -1.0, -1.1], &[-1.5, -1.4, -1.3, 1.0, 1.2]);
    assert_eq!(lim[0], JointLimit::new(-1.5, 1.5));
    assert_eq!(lim[1], JointLimit::new(-1.4, 1.4));
    assert_eq!(lim[4], JointLimit::new(-1.2, 1.1));
}

fn theta_in_limits() -> impl Strategy<Value = Theta> {
    let l = geom().limits;
    (
        l[0].min..l[0].max,
        l[1].min..l[1].max,
        l[2].min..l[2].max,
        l[3].min..l[3].max,
        l[4].min..l[4].max,
    )
        .prop_map(|(a, b, c, d, e)| [a, b, c, d, e])
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 2000,
        failure_persistence: None,
        rng_algorithm: proptest::test_runner::RngAlgorithm::ChaCha,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x11B3),
        ..ProptestConfig::default()
    })]

    /// FK→IK→FK reproduces the pose to 1e-9 m and 1e-9 rad for every in-limit
    /// configuration, from the zero configuration and from the configuration itself.
    #[test]
    fn fk_ik_fk_round_trip(theta in theta_in_limits(), other in theta_in_limits()) {
        let g = geom();
        let target = g.fk(&theta).unwrap();
        for current in [[0.0; 5], theta, other] {
            let sol = g.solve_pose(&target, &current, &opts()).unwrap();
            prop_assert!(g.within_limits(&sol.theta));
            let back = g.fk(&sol.theta).unwrap();
            prop_assert!(back.position_error(&target) < 1e-9);
            prop_assert!(back.orientation_error(&target) < 1e-9);
        }
        // Started at the configuration itself, IK returns it.
        let sol = g.solve_pose(&target, &theta, &opts()).unwrap();
        for i in 0..5 {
            prop_assert!((sol.theta[i] - theta[i]).abs() < 1e-6, "{:?} vs {:?}", sol.theta, theta);
        }
    }

    /// The FK frame is orthonormal and right-handed, and equals the rotation product.
    #[test]
    fn fk_frame_is_orthonormal_right_handed(theta in theta_in_limits()) {
        let p = geom().fk(&theta).unwrap();
        let m = p.rotation.matrix();
        prop_assert!((m.transpose() * m - nalgebra::Matrix3::identity()).norm() < 1e-14);
        prop_assert!((m.determinant() - 1.0).abs() < 1e-14);
        prop_assert!((p.normal() - p.orientation().cross(&p.approach())).norm() < 1e-14);
        let r = Rotation3::from_axis_angle(&Vector3::z_axis(), theta[0])
            * Rotation3::from_axis_angle(&Vector3::y_axis(), -(theta[1] + theta[2]))
            * Rotation3::from_axis_angle(&Vector3::x_axis(), theta[3])
            * Rotation3::from_axis_angle(&Vector3::y_axis(), -theta[4]);
        prop_assert!((r.matrix() - m).norm() < 1e-14);
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 150,
        failure_persistence: None,
        rng_algorithm: proptest::test_runner::RngAlgorithm::ChaCha,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x11B3),
        ..ProptestConfig::default()
    })]

    /// SETPOSITION reaches any position of an in-limit configuration, inside the limits.
    #[test]
    fn setposition_reaches_reachable_positions(theta in theta_in_limits()) {
        let g = geom();
        let target = g.fk(&theta).unwrap().position;
        let sol = g.solve_position(&target, ApproachPreference::Current, &[0.0; 5], &opts()).unwrap();
        prop_assert!(g.within_limits(&sol.theta));
        prop_assert!((g.fk(&sol.theta).unwrap().position - target).norm() < 1e-9);
    }
}

#[test]
fn candidates_cover_the_branches() {
    let g = geom();
    // Wrist centre close to the yaw axis, so reaching over the top is possible too.
    let theta = [0.3, 1.2, 1.0, -0.2, 0.6];
    let target = g.fk(&theta).unwrap();
    let c = g.pose_candidates(&target, &[0.0; 5], &opts()).unwrap();
    assert_eq!(c.len(), 4);
    assert!(
        c.as_slice()
            .iter()
            .all(|c| c.theta.iter().all(|t| t.is_finite()))
    );
    // A 5-DOF arm reaches a full frame only where its normal is perpendicular to the
    // forearm, so the other branches generally miss the orientation; the original
    // configuration's branch is exact.
    let exact: Vec<_> = c
        .as_slice()
        .iter()
        .filter(|c| c.position_error < 1e-9 && c.orientation_error < 1e-9)
        .collect();
    assert!(exact.iter().any(|c| c.branch.shoulder == Shoulder::Front
        && c.branch.elbow == Elbow::Down
        && (c.theta[3] - theta[3]).abs() < 1e-9));
    // Every candidate reaches the position (only the wrist can miss).
    assert!(c.as_slice().iter().all(|c| c.position_error < 0.3));
    let with_approach = g
        .approach_candidates(&target.position, &target.approach(), &[0.0; 5], &opts())
        .unwrap();
    assert_eq!(with_approach.len(), 8);
    let exact_approach = with_approach
        .as_slice()
        .iter()
        .filter(|c| c.position_error < 1e-9 && c.orientation_error < 1e-9)
        .count();
    assert_eq!(exact_approach, 8, "{:?}", with_approach.as_slice());
}

/// Wide limits: the other branches become valid, and the choice follows `current`.
#[test]
fn choice_is_nearest_to_current() {
    let mut g = geom();
    g.limits = [JointLimit::new(-PI, PI); 5];
    let theta = [0.3, 0.4, 0.5, -0.2, 0.6];
    let target = g.fk(&theta).unwrap();
    let all = g.pose_candidates(&target, &[0.0; 5], &opts()).unwrap();
    let exact = all
        .as_slice()
        .iter()
        .filter(|c| c.position_error < 1e-9 && c.orientation_error < 1e-9);
    for c in exact {
        let sol = g.solve_pose(&target, &c.theta, &opts()).unwrap();
        assert_eq!(sol.branch, c.branch);
    }
    // Deterministic.
    let a = g.solve_pose(&target, &[0.1; 5], &opts()).unwrap();
    let b = g.solve_pose(&target, &[0.1; 5], &opts()).unwrap();
    assert_eq!(a, b);
}

fn stretched_target(extra: f64) -> Pose {
    // Fully stretched along +x: wrist at L1 + L2 + L4, approach +x.
    let g = geom();
    let x = g.l1 + g.l2 + g.l4 + g.l5 + extra;
    Pose::new(Vector3::new(x, 0.0, 0.0), Rotation3::identity())
}

#[test]
fn reach_at_inside_and_beyond() {
    let g = geom();
    let o = opts();
    let at = g.solve_pose(&stretched_target(0.0), &[0.0; 5], &o).unwrap();
    assert!(at.theta.iter().all(|t| t.abs() < 1e-6), "{:?}", at.theta);
    let inside = g
        .solve_pose(&stretched_target(-1e-6), &[0.0; 5], &o)
        .unwrap();
    assert!(
        g.fk(&inside.theta)
            .unwrap()
            .position_error(&stretched_target(-1e-6))
            < 1e-9
    );
    // Within the position tolerance beyond: accepted (clamped by at most 1e-6 m).
    assert!(g.solve_pose(&stretched_target(5e-7), &[0.0; 5], &o).is_ok());
    for extra in [2e-6, 1e-4, 0.01, 1.0, 1e6, 1e300] {
        let e = g
            .solve_pose(&stretched_target(extra), &[0.0; 5], &o)
            .unwrap_err();
        match e {
            PioneerIkError::OutOfReach { distance, min, max } => {
                assert!(distance.is_finite() && distance > max && min >= 0.0);
            }
            other => panic!("expected OutOfReach for +{extra}: {other:?}"),
        }
        assert!(e.is_out_of_reach());
    }
    // Wrist centre closer to the shoulder than |L2 - L4| = 0.02225 m (with L1 = 0 so
    // that reaching over the top does not help either).
    let mut g0 = g;
    g0.l1 = 0.0;
    let near = Pose::new(Vector3::new(0.001 + g.l5, 0.0, 0.0), Rotation3::identity());
    assert!(matches!(
        g0.solve_pose(&near, &[0.0; 5], &o),
        Err(PioneerIkError::OutOfReach { .. })
    ));
}

#[test]
fn inconsistent_orientation_is_reported_not_approximated() {
    let g = geom();
    let theta = [0.3, 0.4, 0.5, -0.2, 0.6];
    let target = g.fk(&theta).unwrap();
    // Roll the frame about its approach: the normal leaves the plane perpendicular to
    // the forearm, which the 5-DOF wrist cannot follow.
    for (angle, ok) in [(1e-8, true), (1e-5, false), (0.1, false)] {
        let rolled = Pose::new(
            target.position,
            target.rotation * Rotation3::from_axis_angle(&Vector3::x_axis(), angle),
        );
        let r = g.solve_pose(&rolled, &[0.0; 5], &opts());
        if ok {
            assert!(r.is_ok(), "{angle}: {r:?}");
        } else {
            match r {
                Err(PioneerIkError::UnreachableOrientation { error }) => {
                    assert!(error > 1e-6 && error.is_finite())
                }
                other => panic!("{angle}: {other:?}"),
            }
        }
    }
}

#[test]
fn outside_the_limits_is_out_of_reach() {
    let mut g = geom();
    g.limits[0] = JointLimit::new(-0.5, 0.5);
    let target = g.fk(&[1.0, 0.2, 0.3, 0.1, 0.2]).unwrap();
    let e = g.solve_pose(&target, &[0.0; 5], &opts()).unwrap_err();
    assert_eq!(e, PioneerIkError::OutsideJointLimits);
    assert!(e.is_out_of_reach());
    // On the limit itself (round-off tolerated).
    let on = g.fk(&[0.5, 0.2, 0.3, 0.1, 0.2]).unwrap();
    let sol = g.solve_pose(&on, &[0.0; 5], &opts()).unwrap();
    assert!((sol.theta[0] - 0.5).abs() < 1e-9 && sol.theta[0] <= 0.5);
}

#[test]
fn nan_and_bad_input_are_errors() {
    let g = geom();
    let o = opts();
    let good = g.fk(&[0.1; 5]).unwrap();
    assert_eq!(g.fk(&[f64::NAN; 5]), Err(PioneerFkError::NonFinite));
    let mut bad = good;
    bad.position.x = f64::NAN;
    assert_eq!(
        g.solve_pose(&bad, &[0.0; 5], &o),
        Err(PioneerIkError::NonFinite)
    );
    let mut cur = [0.0; 5];
    cur[2] = f64::INFINITY;
    assert_eq!(
        g.solve_pose(&good, &cur, &o),
        Err(PioneerIkError::NonFinite)
    );
    assert!(matches!(
        g.solve_setpose(
            &good.position,
            &Vector3::zeros(),
            &Vector3::z(),
            &[0.0; 5],
            &o
        ),
        Err(PioneerIkError::Frame(_))
    ));
    assert!(matches!(
        g.solve_setpose(&good.position, &Vector3::x(), &Vector3::x(), &[0.0; 5], &o),
        Err(PioneerIkError::Frame(_))
    ));
    let p = Vector3::new(f64::NAN, 0.0, 0.0);
    assert_eq!(
        g.solve_position(&p, ApproachPreference::Down, &[0.0; 5], &o),
        Err(PioneerIkError::NonFinite)
    );
    let mut bad_opts = o;
    bad_opts.position_tolerance = f64::NAN;
    assert_eq!(
        g.solve_pose(&good, &[0.0; 5], &bad_opts),
        Err(PioneerIkError::InvalidOptions)
    );
    let mut bad_geom = g;
    bad_geom.l2 = -1.0;
    assert!(matches!(
        bad_geom.solve_pose(&good, &[0.0; 5], &o),
        Err(PioneerIkError::Geometry(_))
    ));
    assert!(matches!(
        g.vecmove(
            &[0.0; 5],
            &Vector3::zeros(),
            0.1,
            &VecMoveOptions::default()
        ),
        Err(VecMoveError::ZeroDirection)
    ));
    assert!(matches!(
        g.vecmove(
            &[0.0; 5],
            &Vector3::x(),
            f64::NAN,
            &VecMoveOptions::default()
        ),
        Err(VecMoveError::NonFinite)
    ));
}

#[test]
fn setpose_from_player_vectors_in_the_robot_frame() {
    let g = geom();
    let theta = [0.2, 0.3, 0.4, 0.0, -0.3];
    let robot = g.fk_robot(&theta).unwrap();
    // Unnormalised vectors as a client might send them.
    let sol = g
        .solve_setpose(
            &robot.position,
            &(robot.approach() * 2.0),
            &(robot.orientation() * 0.5),
            &[0.0; 5],
            &opts(),
        )
        .unwrap();
    let back = g.fk_robot(&sol.theta).unwrap();
    assert!(back.position_error(&robot) < 1e-9 && back.orientation_error(&robot) < 1e-9);
}

#[test]
fn setposition_pointing_down_and_out_of_reach() {
    let g = geom();
    let target = Vector3::new(0.3, 0.05, -0.15);
    let sol = g
        .solve_position(&target, ApproachPreference::Down, &[0.0; 5], &opts())
        .unwrap();
    let pose = g.fk(&sol.theta).unwrap();
    assert!((pose.position - target).norm() < 1e-6);
    assert!(
        (pose.approach() + Vector3::z()).norm() < 1e-6,
        "{:?}",
        pose.approach()
    );
    let far = Vector3::new(0.6, 0.0, 0.2);
    assert!(matches!(
        g.solve_position(&far, ApproachPreference::Current, &[0.0; 5], &opts()),
        Err(PioneerIkError::OutOfReach { .. })
    ));
    // Behind the robot: within the geometric reach but never within the limits.
    let behind = Vector3::new(-0.25, 0.0, -0.1);
    let e = g
        .solve_position(&behind, ApproachPreference::Current, &[0.0; 5], &opts())
        .unwrap_err();
    assert!(e.is_out_of_reach(), "{e:?}");
}

#[test]
fn vecmove_follows_the_line_with_bounded_deviation() {
    let g = geom();
    let start = [0.1, 0.3, 0.6, 0.2, 0.4];
    let p0 = g.fk(&start).unwrap();
    let dir = Vector3::new(0.3, -1.0, -0.4).normalize();
    let len = 0.08;
    let options = VecMoveOptions {
        max_deviation: 5e-4,
        ..VecMoveOptions::default()
    };
    let mut last = None;
    let mut count = 0;
    for w in g.vecmove(&start, &dir, len, &options).unwrap() {
        let w = w.unwrap();
        count += 1;
        assert!(w.deviation <= 5e-4);
        assert!(g.within_limits(&w.theta));
        let pose = g.fk(&w.theta).unwrap();
        let expect = p0.position + dir * w.distance;
        assert!((pose.position - expect).norm() < 1e-6);
        assert!((pose.approach() - p0.approach()).norm() < 1e-6);
        last = Some(w);
    }
    let last = last.unwrap();
    assert!((last.distance - len).abs() < 1e-15);
    assert!(count >= 4, "{count} waypoints");
}

#[test]
fn vecmove_out_of_reach_stops_with_an_error() {
    let g = geom();
    let start = [0.0, 0.2, 0.3, 0.0, 0.0];
    let items: Vec<_> = g
        .vecmove(&start, &Vector3::x(), 0.5, &VecMoveOptions::default())
        .unwrap()
        .collect();
    let (last, before) = items.split_last().unwrap();
    assert!(before.iter().all(|w| w.is_ok()));
    match last {
        Err(VecMoveError::Unreachable { distance, cause }) => {
            assert!(distance.is_finite() && *distance < 0.5);
            assert!(cause.is_out_of_reach());
        }
        other => panic!("{other:?}"),
    }
    assert!(items.len() > 1);
    // Zero length: no waypoint.
    assert_eq!(
        g.vecmove(&start, &Vector3::x(), 0.0, &VecMoveOptions::default())
            .unwrap()
            .count(),
        0
    );
    let _ = FRAC_PI_2;
}

/// When the preferred approach is impossible, SETPOSITION takes the in-plane approach
/// (gripper level, wrist roll 0 or π) nearest to it: one step closer is infeasible.
#[test]
fn setposition_falls_back_to_the_nearest_in_plane_approach() {
    let g = geom();
    let o = opts();
    let target = Vector3::new(0.22, 0.08, -0.25);
    let preferred = Vector3::new(1.0, 0.0, 0.0);
    assert!(
        g.solve_position_approach(&target, &preferred, &[0.0; 5], &o)
            .is_err()
    );
    let sol = g
        .solve_position(
            &target,
            ApproachPreference::Direction(preferred),
            &[0.0; 5],
            &o,
        )
        .unwrap();
    let pose = g.fk(&sol.theta).unwrap();
    assert!((pose.position - target).norm() < 1e-6);
    let a = pose.approach();
    // In the vertical plane through the yaw axis and the target.
    let plane_normal = Vector3::new(-target.y, target.x, 0.0).normalize();
    assert!(a.dot(&plane_normal).abs() < 1e-6, "{a:?}");
    // Nearest: tilting it 1e-4 rad towards the preferred elevation fails.
    let radial = Vector3::new(target.x, target.y, 0.0).normalize();
    let phi = a.z.atan2(a.dot(&radial));
    let closer = phi + 1e-4 * (0.0 - phi).signum();
    let a2 = radial * closer.cos() + Vector3::z() * closer.sin();
    assert!(
        g.solve_position_approach(&target, &a2, &[0.0; 5], &o)
            .is_err()
    );
}

/// Positions reachable only with θ1 on its limit (the target's vertical plane is
/// beyond it) are still found.
#[test]
fn setposition_at_the_yaw_limit() {
    let g = geom();
    let theta = [
        1.5124862068729268,
        -1.5480789923911729,
        -0.15774691699986487,
        -1.4035144795892425,
        0.1289359815486788,
    ];
    let target = g.fk(&theta).unwrap().position;
    let sol = g
        .solve_position(&target, ApproachPreference::Current, &[0.0; 5], &opts())
        .unwrap();
    assert!(g.within_limits(&sol.theta));
    assert!((g.fk(&sol.theta).unwrap().position - target).norm() < 1e-6);
}

/// Issue 12, item 8: a huge direction is a direction (its norm overflows; scaling by the
/// largest component first keeps it), the zero vector is not.
#[test]
fn vecmove_direction_of_huge_components_is_normalised_without_overflow() {
    let g = geom();
    let start = [0.1, 0.3, 0.6, 0.2, 0.4];
    let options = VecMoveOptions::default();
    let plan = |dir: Vector3<f64>| -> Vec<[f64; 5]> {
        g.vecmove(&start, &dir, 0.02, &options)
            .unwrap()
            .map(|w| w.unwrap().theta)
            .collect()
    };
    let same = |a: &[[f64; 5]], b: &[[f64; 5]]| {
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .all(|(x, y)| x.iter().zip(y).all(|(p, q)| (p - q).abs() < 1e-9))
    };
    let small = plan(Vector3::new(0.5, -1.0, -0.5));
    let huge = plan(Vector3::new(0.5e308, -1e308, -0.5e308));
    assert!(!huge.is_empty());
    assert!(same(&small, &huge), "{small:?} vs {huge:?}");
    let p0 = g.fk(&start).unwrap().position;
    let end = g.fk(huge.last().unwrap()).unwrap().position;
    assert!(
        ((end - p0).norm() - 0.02).abs() < 1e-6,
        "{}",
        (end - p0).norm()
    );
    // Subnormal components are a direction too; zero is not.
    assert!(same(
        &plan(Vector3::new(0.5e-320, -1e-320, -0.5e-320)),
        &small
    ));
    assert!(matches!(
        g.vecmove(&start, &Vector3::zeros(), 0.02, &options),
        Err(VecMoveError::ZeroDirection)
    ));
    let u =
        limber_kinematics::unit_direction(&Vector3::new(f64::MAX, -f64::MAX, f64::MAX)).unwrap();
    assert!((u - Vector3::new(1.0, -1.0, 1.0) / 3f64.sqrt()).norm() < 1e-15);
    assert_eq!(limber_kinematics::unit_direction(&Vector3::zeros()), None);
}
