//! The message line and its log (`M`): what the editor says after a key.

use super::{App, LOG_LIMIT, Level, Message};

impl App {
    pub(super) fn say(&mut self, level: Level, text: impl Into<String>) {
        let message = Message {
            text: text.into(),
            level,
        };
        self.keep_in_log(message.clone());
        self.message = Some(message);
    }

    /// Keep `message` in the log (`M`). A message repeated at once (the
    /// same unbound key pressed again) is logged once.
    fn keep_in_log(&mut self, message: Message) {
        if self.log.last() != Some(&message) {
            if self.log.len() >= LOG_LIMIT {
                self.log.remove(0);
            }
            self.log.push(message);
        }
    }

    /// Every message so far, oldest first.
    pub fn log(&self) -> &[Message] {
        &self.log
    }

    /// An informational message, unless the edit already left a diagnostic.
    pub(super) fn say_info(&mut self, text: impl Into<String>) {
        if self.message.is_none() {
            self.say(Level::Info, text);
        }
    }

    /// An informative message that is always logged (`M`), and shown
    /// unless this key already put a message on the line (a warning from
    /// the edit keeps it).
    pub(super) fn tell(&mut self, text: impl Into<String>) {
        if self.message.is_none() {
            self.say(Level::Info, text);
        } else {
            self.keep_in_log(Message {
                text: text.into(),
                level: Level::Info,
            });
        }
    }
}
