// The check of wasm_clip.mjs, run inside the browser: the checks of tests/capi/capi_clip_test.c
// through the JavaScript API (chaintube.mjs). The motion-rig export's cable carriage-cable is
// clamped on the base plate and runs through a sliding clip on the carriage and a guide clip on
// the plate; the carriage slides along x as a scenario drives it (setNodeTransform, 5 mm a
// frame): out to +50 mm, back to -50 mm and home. After every update the cable's frame result is
// OK (violations within 1e-9), it passes through every clip's centre along the clip's axis (the
// held segment's points at their rest distances from the centre, 1e-9 m; gap 0), the carriage's
// clip has moved with the carriage, every segment is within its band, the rest lengths are as
// loaded and each slide lies on its held segment and within its stops, with the hose's arc to the
// centre equal to the slide within the band; and the cable has slid through the carriage's clip
// at least 40 mm each way. Then the clip functions' refusals. No file or Node API: the caller
// hands it the module and the bytes.
export const TOLERANCE = 1e-9;

/**
 * api: the chaintube.mjs module; chaintube: a loaded ChainTube; bytes: the motion-rig export
 * (.glb); name: its file name. Returns { checks, failures: [text], frames, slideHome, slideMin,
 * slideMax }.
 */
export function checkClips(api, chaintube, bytes, name) {
  const failures = [];
  let checks = 0;
  const expect = (condition, what) => {
    ++checks;
    if (!condition) failures.push(what);
  };
  const distance = (a, i, b, j) => Math.hypot(a[i] - b[j], a[i + 1] - b[j + 1], a[i + 2] - b[j + 2]);

  const rig = chaintube.loadMemory(name, bytes);
  const hose = rig.findHose('carriage-cable');
  const other = rig.findHose('carriage-feed');
  const carriage = rig.findNode('carriage');
  const plate = rig.findNode('base_plate');
  const info = rig.hoseInfo(hose);
  const { restLengths: rest, expansionCoefficient: band } = rig.restLengths(hose);
  const prefix = [0];
  rest.forEach((length, s) => prefix.push(prefix[s] + length));
  expect(rig.clipCount(hose) === 2, `carriage-cable has ${rig.clipCount(hose)} clips, expected 2`);
  expect(rig.clipCount(other) === 0, 'carriage-feed has clips');
  expect(rest.length === info.pointCount - 1, `${rest.length} rest lengths for ${info.pointCount} points`);
  expect(band === 0.02, `band ${band}, expected the cable bundle's 0.02`);
  expect(Math.abs(prefix[rest.length] - info.restLength) <= TOLERANCE, 'the rest lengths do not sum to restLength');
  const clips = [rig.clipInfo(hose, 0), rig.clipInfo(hose, 1)];
  expect(clips[0].node === carriage && clips[1].node === plate,
    `the clips are on nodes ${clips[0].node} and ${clips[1].node}, expected the carriage and the base plate`);
  expect(!clips[0].turning && clips[0].slideMin === 0 && Math.abs(clips[0].slideMax - info.restLength) <= TOLERANCE,
    `clip 0: turning ${clips[0].turning}, stops ${clips[0].slideMin} ... ${clips[0].slideMax}`);

  // The cable after an update; returns the carriage's clip.
  function checkCable(when) {
    const result = rig.hoseResult(hose);
    expect(result.status === api.HoseStatus.OK, `${when}: status ${result.status}`);
    expect(result.lengthViolation <= TOLERANCE && result.angleViolation <= TOLERANCE,
      `${when}: violations ${result.lengthViolation} (length), ${result.angleViolation} rad`);
    expect(rig.hoseInfo(hose).restLength === info.restLength, `${when}: rest length changed`);
    const now = rig.restLengths(hose);
    expect(now.expansionCoefficient === band && now.restLengths.every((l, s) => l === rest[s]),
      `${when}: rest lengths or band changed`);
    const world = Float64Array.from(rig.jointPosesF64(hose, { local: false }).world);
    for (let s = 0; s < rest.length; ++s) {
      const stretch = distance(world, 7 * (s + 1), world, 7 * s) / rest[s] - 1;
      expect(Math.abs(stretch) <= band + TOLERANCE,
        `${when}: segment ${s} stretched ${(100 * stretch).toPrecision(3)} % (band ${100 * band} %)`);
    }
    let carriageClip = null;
    for (let k = 0; k < rig.clipCount(hose); ++k) {
      const clip = rig.clipInfo(hose, k);
      const j = clip.segment;
      if (!(j >= 0 && j + 1 <= rest.length)) {
        expect(false, `${when}: clip ${k} segment ${j}`);
        continue;
      }
      expect(Math.abs(Math.hypot(...clip.axis) - 1) <= TOLERANCE, `${when}: clip ${k} axis not unit`);
      expect(clip.gap <= TOLERANCE, `${when}: clip ${k} gap ${clip.gap} m`);
      expect(clip.slideMin <= clip.slide && clip.slide <= clip.slideMax, `${when}: clip ${k} slide beyond its stops`);
      expect(prefix[j] <= clip.slide + TOLERANCE && clip.slide <= prefix[j + 1] + TOLERANCE,
        `${when}: clip ${k} slide ${clip.slide} is not on its segment ${j}`);
      // Through the centre along the axis: each held point at its rest distance from it.
      const along = clip.slide - prefix[j];
      for (let a = 0; a < 3; ++a) {
        const first = clip.centre[a] - along * clip.axis[a];
        const second = clip.centre[a] + (rest[j] - along) * clip.axis[a];
        expect(Math.abs(world[7 * j + a] - first) <= TOLERANCE && Math.abs(world[7 * (j + 1) + a] - second) <= TOLERANCE,
          `${when}: clip ${k}: point ${j} or ${j + 1} off the clip's axis (coordinate ${a}: ` +
          `${world[7 * j + a]}, ${world[7 * (j + 1) + a]}; expected ${first}, ${second})`);
      }
      // The hose's arc from point 0 to the centre is the slide within the band.
      let arc = along;
      for (let s = 0; s < j; ++s) arc += distance(world, 7 * (s + 1), world, 7 * s);
      expect(Math.abs(arc / clip.slide - 1) <= band + TOLERANCE,
        `${when}: clip ${k}: arc ${arc} m to the centre for a slide of ${clip.slide} m`);
      if (clip.node === carriage) carriageClip = clip;
    }
    return carriageClip;
  }

  const home = checkCable('as loaded');
  expect(Math.abs(home.slide - 0.3) <= TOLERANCE, `the carriage clip's place ${home.slide}, exported 0.3`);
  const trs = Array.from(rig.nodeTransform(carriage));
  const x0 = trs[0];
  let frames = 0, slideMin = home.slide, slideMax = home.slide;
  // Out to +50 mm, back to -50 mm, home: 5 mm a frame.
  for (let step = 1; step <= 40; ++step) {
    const millimetres = step <= 10 ? 5 * step : step <= 30 ? 100 - 5 * step : 5 * step - 200;
    const when = `frame ${step}, carriage at ${millimetres} mm`;
    trs[0] = x0 + 0.001 * millimetres;
    rig.setNodeTransform(carriage, trs);
    rig.update();
    ++frames;
    const clip = checkCable(when);
    // The clip goes with the carriage (the sample's parents are identity transforms).
    const expected = [home.centre[0] + 0.001 * millimetres, home.centre[1], home.centre[2]];
    expect(clip.centre.every((x, a) => Math.abs(x - expected[a]) <= TOLERANCE),
      `${when}: the clip's centre ${clip.centre}, expected ${expected}`);
    slideMin = Math.min(slideMin, clip.slide);
    slideMax = Math.max(slideMax, clip.slide);
    if (millimetres === 50)
      expect(clip.slide - home.slide >= 0.04, `${when}: slid ${clip.slide - home.slide} m, expected 0.04+`);
    if (millimetres === -50)
      expect(home.slide - clip.slide >= 0.04, `${when}: slid back ${home.slide - clip.slide} m, expected 0.04+`);
  }

  // Refusals: a ChainTubeError with the status and the C ABI's message.
  function expectError(what, status, fragment, call) {
    ++checks;
    try {
      call();
      failures.push(`${what}: no error`);
    } catch (error) {
      if (!(error instanceof api.ChainTubeError)) failures.push(`${what}: ${error} is not a ChainTubeError`);
      else if (error.status !== status || !error.message.includes(fragment))
        failures.push(`${what}: ${error.statusName} "${error.message}", expected status ${status} and "${fragment}"`);
    }
  }
  expectError('clip out of range', api.Status.ERROR_OUT_OF_RANGE, 'clip 2 is out of range', () => rig.clipInfo(hose, 2));
  expectError('a hose without clips', api.Status.ERROR_OUT_OF_RANGE, 'has 0 clips', () => rig.clipInfo(other, 0));
  expectError('a fractional clip', api.Status.ERROR_INVALID_ARGUMENT, 'clip is 0.5', () => rig.clipInfo(hose, 0.5));
  expectError('hose out of range', api.Status.ERROR_OUT_OF_RANGE, 'hose 99 is out of range', () => rig.clipCount(99));
  rig.destroy();
  return { checks, failures, frames, slideHome: home.slide, slideMin, slideMax };
}
