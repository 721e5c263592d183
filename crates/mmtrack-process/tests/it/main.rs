//! Every pipeline of `mmtrack-process` called as a library (no binary):
//! simulate a small recording, process it, read the tables back.

mod pipelines;
