// Runs a Flamenco 3 job compiler script (farm/flamenco/dwivedi-bake.js) outside Flamenco, for
// tests/farm/test_flamenco_job.py: the script is evaluated in a fresh context holding the globals
// Flamenco Manager gives job compilers and this script uses (author.Task, author.Command, path,
// print), reduced to recording what compileJob authors. It is NOT Flamenco: the Manager's goja
// engine, its settings validation and its Workers are not run here (docs/farm.md says so).
//
//   node flamenco_compile.js SCRIPT SETTINGS_JSON
// prints {"job_type": JOB_TYPE, "tasks": [{name, type, commands: [{name, parameters}],
// dependencies: [task names]}]} as JSON; a compileJob that throws: exit 1, its message on stderr.
"use strict";
const fs = require("fs");
const vm = require("vm");

const [script, settingsJson] = process.argv.slice(2);
const tasks = [];
const author = {
    Task(name, type) {
        const task = { name, type, commands: [], dependencies: [] };
        task.addCommand = (command) => { task.commands.push(command); };
        task.addDependency = (other) => { task.dependencies.push(other.name); };
        return task;
    },
    Command(name, parameters) {
        return { name, parameters };
    },
};
const job = {
    settings: JSON.parse(settingsJson),
    created: new Date(0),
    addTask(task) { tasks.push(task); },
};
const context = vm.createContext({ author, path: require("path").posix, print: (...a) => console.error(...a) });
vm.runInContext(fs.readFileSync(script, "utf8") + "\n;globalThis.JOB_TYPE = JOB_TYPE;", context, { filename: script });
try {
    context.compileJob(job);
} catch (error) {
    console.error(String(error));
    process.exit(1);
}
const plain = tasks.map((t) => ({ name: t.name, type: t.type, commands: t.commands, dependencies: t.dependencies }));
process.stdout.write(JSON.stringify({ job_type: context.JOB_TYPE, tasks: plain }) + "\n");
