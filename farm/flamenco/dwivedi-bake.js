// A Flamenco 3 job type for a dwivedi split bake (docs/farm.md): one task a chunk of sample
// indices (`dwivedi bake SCENE --spp N --samples FIRST:COUNT`), then one merge task that depends
// on all of them (`dwivedi merge`), so the merge never runs when a chunk failed. Install: copy
// this file into the `scripts` folder beside flamenco-manager and restart the Manager.
//
// The job works on a folder written by the Blender add-on's "Export for a Farm" (or by
// `python3 -m dwivedi.farm`): the scene file is in it, the chunks go to FOLDER/parts, the merge
// writes FOLDER/NAME.exr, .png and .json. The folder must be on storage every Worker sees at the
// same path (Flamenco's shared storage). The Workers run `dwivedi` (settings.dwivedi: a name on
// their PATH, a full path, or a Manager variable such as "{dwivedi}"); the tasks are of type
// "misc" and use Flamenco's `exec` command (parameters `exe` and `args`; no shell). Plain
// ES5/ES6 (no spread, no destructuring) for the Manager's JavaScript engine (goja).
//
// The chunks are cut as python_shim/dwivedi/farm.py's split_samples cuts them (sizes differing by
// at most one, in order), so the same settings give the same ranges as the exported chunks.txt.

const JOB_TYPE = {
    label: "Dwivedi Subsurface Bake",
    description: "A dwivedi bake split into chunks of samples, merged into exactly the one-machine result",
    settings: [
        { key: "folder", type: "string", subtype: "dir_path", required: true, visible: "submission",
          eval: "abspath(C.scene.dwivedi_farm.folder)",
          description: "The folder 'Export for a Farm' wrote (its path as the Workers see it)" },
        { key: "scene_file", type: "string", required: true, default: "dwivedi_scene.json", visible: "submission",
          description: "The scene file in that folder" },
        { key: "samples", type: "int32", required: true, default: 64, propargs: { min: 1 },
          eval: "C.scene.dwivedi_bake.samples", visible: "submission",
          description: "Samples per pixel in all (every chunk is told the total)" },
        { key: "chunks", type: "int32", required: true, default: 8, propargs: { min: 1 },
          eval: "C.scene.dwivedi_farm.chunks", visible: "submission",
          description: "How many tasks the samples are cut into (at most the samples)" },
        { key: "seed", type: "int32", required: true, default: 0, propargs: { min: 0 },
          eval: "C.scene.dwivedi_bake.seed", visible: "submission", description: "Random seed" },
        { key: "threads", type: "int32", default: 0, propargs: { min: 0 }, visible: "submission",
          description: "Threads a chunk uses (0: all the Worker's cores); the image does not depend on it" },
        { key: "output_name", type: "string", required: true, default: "merged", visible: "submission",
          description: "Name of the merged EXR, PNG and JSON in the folder" },
        { key: "dwivedi", type: "string", required: true, default: "dwivedi", visible: "submission",
          description: "The dwivedi command on the Workers" },
    ],
};

// [first, count] ranges of `samples` sample indices cut into `chunks` in order.
function splitSamples(samples, chunks) {
    if (!Number.isInteger(samples) || samples < 1 || samples > 16777216) {
        throw `samples must be a whole number from 1 to 16777216, not ${samples}`;
    }
    if (!Number.isInteger(chunks) || chunks < 1 || chunks > samples) {
        throw `chunks must be a whole number from 1 to the samples (${samples}), not ${chunks}`;
    }
    const base = Math.floor(samples / chunks);
    const extra = samples % chunks;
    const ranges = [];
    let first = 0;
    for (let i = 0; i < chunks; i++) {
        const count = base + (i < extra ? 1 : 0);
        ranges.push([first, count]);
        first += count;
    }
    return ranges;
}

// The output name as dwivedi.farm allows it: a plain file name, no folders or shell characters.
function checkedName(name) {
    if (!/^[A-Za-z0-9_][A-Za-z0-9._-]{0,99}$/.test(name)) {
        throw `output_name '${name}' must be letters, digits, '.', '_' or '-'`;
    }
    return name;
}

function chunkPart(folder, index) {
    return path.join(folder, "parts", `chunk-${index}`);
}

function compileJob(job) {
    const settings = job.settings;
    const folder = settings.folder;
    if (!folder) {
        throw "the job has no folder (Export for a Farm writes one)";
    }
    const name = checkedName(settings.output_name);
    const scene = path.join(folder, settings.scene_file);
    const ranges = splitSamples(settings.samples, settings.chunks);
    const threads = settings.threads > 0 ? ["--threads", String(settings.threads)] : [];

    const chunkTasks = [];
    const parts = [];
    for (let index = 0; index < ranges.length; index++) {
        const first = ranges[index][0];
        const count = ranges[index][1];
        const task = author.Task(`chunk-${index} (samples ${first}:${count})`, "misc");
        const args = ["bake", scene, "--spp", String(settings.samples), "--seed", String(settings.seed)]
            .concat(threads, ["--samples", `${first}:${count}`, "--out", chunkPart(folder, index), "--quiet"]);
        task.addCommand(author.Command("exec", { exe: settings.dwivedi, args: args }));
        job.addTask(task);
        chunkTasks.push(task);
        parts.push(chunkPart(folder, index) + ".dwvpart");
    }

    // Every chunk's file by name (never a glob): a missing one is named by the merge, a stray
    // file in parts/ is not taken.
    const merge = author.Task("merge", "misc");
    merge.addCommand(author.Command("exec", {
        exe: settings.dwivedi,
        args: ["merge"].concat(parts, ["--out", path.join(folder, name)]),
    }));
    for (const task of chunkTasks) {
        merge.addDependency(task);
    }
    job.addTask(merge);
    print(`dwivedi bake: ${ranges.length} chunks of ${settings.samples} samples, merged into ${path.join(folder, name)}.exr`);
}
