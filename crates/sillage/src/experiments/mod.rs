pub mod bedload;
